# SPDX-License-Identifier: LGPL-2.1-or-later
# A Debian package of what `cmake --install` installs (the programs, libdefocus with its headers
# and CMake/pkg-config files, the GStreamer plugin, the batch scripts), so that a cluster admin
# installs one package on every node:
#   cmake --build build && (cd build && cpack -G DEB)     ->  build/defocus_0.1.0_amd64.deb
# A build configured with -DCMAKE_INSTALL_PREFIX=/usr gives a package for /usr (the library in
# lib/<multiarch>, the plugin where GStreamer looks); any other build's package installs under
# /opt/defocus (programs in /opt/defocus/bin, found by their RPATH's libdefocus).
# The Debian dependencies are the packages of the shared libraries the binaries link
# (dpkg-shlibdeps), and EGL and OpenGL, which libepoxy opens at run time (no binary links them);
# Mesa's EGL is recommended for nodes without a GPU driver's (llvmpipe).
if(CMAKE_INSTALL_PREFIX STREQUAL "/usr")
  set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
else()
  set(CPACK_PACKAGING_INSTALL_PREFIX /opt/defocus)
endif()
set(CPACK_PACKAGE_NAME defocus)
set(CPACK_PACKAGE_VENDOR defocus)
set(CPACK_PACKAGE_CONTACT "defocus maintainers <defocus@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "depth of field with polygonal bokeh for RGB-D video, on headless OpenGL")
set(CPACK_PACKAGE_DESCRIPTION "defocus renders depth of field for RGB-D video on EGL (a GPU, or
Mesa's llvmpipe where there is none): the defocus command line, with --batch for many clips
(Slurm array tasks: share/defocus/defocus.sbatch), defocus-preview, defocus-synthetic and
defocus-bench; libdefocus with its C++ headers; the GStreamer elements defocus and defocussrc.")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# libdefocus is the package's own: the binaries find it by their RPATH ($ORIGIN), which CPack
# lets dpkg-shlibdeps resolve inside the package.
set(CPACK_DEBIAN_PACKAGE_DEPENDS "libegl1, libopengl0 | libgl1")
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "libegl-mesa0, libgl1-mesa-dri")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "parallel, slurm-client, gstreamer1.0-tools")
include(CPack)
