#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# The README's first command on a fresh machine: installs the Debian packages that building and the
# demo need when missing (scripts/setup.sh without options: no test-only packages), builds, renders
# the bundled TUM clip with depth of field (a video + a contact sheet of every view), says where.
#   scripts/demo.sh
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh" "$root/build"

cd "$root"
mkdir -p out
# Focus on the monitor and keyboard (1 m) at f/1.4: the desk stays sharp, the person and the wall
# behind blur with hexagonal bokeh. Frame 9 is the sharpest of the clip, so the sheet shows it.
build/defocus data/tum_fr1_rpy -y -o out/tum_defocus.mp4 --focus 1.0 --f-number 1.4 \
  --contact-sheet out/tum_contact_sheet.png --contact-frame 9

echo
echo "demo: depth-of-field video: $root/out/tum_defocus.mp4"
echo "demo: every view of frame 9: $root/out/tum_contact_sheet.png"
