// SPDX-License-Identifier: LGPL-2.1-or-later
// What a file's name says: its extension in lower case, whether it names a video clip, and the
// natural order in which numbered frames sort by number ("frame2" before "frame10").
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace defocus {

/// The extension with its dot, in lower case (ASCII): "clip.MP4" -> ".mp4", "rgb" -> "".
std::string lowerExtension(const std::filesystem::path& file);

/// True when the extension, in any case, is a video container read as a clip: .mp4, .avi, .mkv,
/// .mov, .m4v or .webm.
bool isVideoFile(const std::filesystem::path& file);

/// Natural order of names: runs of decimal digits compare by value ("d2" before "d10"; leading
/// zeros do not count), everything else byte by byte. Names equal by value ("f01" and "f1") are
/// ordered as plain strings, so the order is total: the same names sort into the same list
/// whatever order a folder listed them in.
bool naturalLess(std::string_view a, std::string_view b);

} // namespace defocus
