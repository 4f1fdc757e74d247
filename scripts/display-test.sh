#!/usr/bin/env bash
# SPDX-License-Identifier: LGPL-2.1-or-later
# Runs the display probe (tests/display_probe.cpp) against a real window: starts Xvfb with its
# framebuffer kept in a file (the probe's screenshots), and lets the probe drive defocus-preview
# with xdotool. docs/preview.md.
#   scripts/display-test.sh PROBE PREVIEW      (CTest: ctest -L display)
# Exit: 0 passed, 1 failed, 77 skipped (Xvfb cannot start here: not installed and no root to
# install it, or the server does not come up). xvfb and xdotool are installed when missing.
set -euo pipefail
probe=$(readlink -f "${1:?usage: $0 PROBE PREVIEW}")
preview=$(readlink -f "${2:?usage: $0 PROBE PREVIEW}")

say() { printf 'display-test: %s\n' "$*"; }
skip() { say "SKIP: $*"; exit 77; }
fail() { say "FAIL: $*"; exit 1; }

[ -x "$probe" ] || fail "no probe binary at $probe"
[ -x "$preview" ] || fail "no defocus-preview at $preview"

# ---- packages, installed only when missing (the pattern of scripts/setup.sh) ----
# xvfb: the X server with no screen; xdotool: key presses, clicks and the window's geometry.
packages=(xvfb xdotool)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null && sudo -n true 2>/dev/null || skip "needs ${missing[*]}; no root to install them"
    sudo="sudo -n"
  fi
  say "installing ${missing[*]}"
  log=$(mktemp)
  { $sudo apt-get update -q && $sudo env DEBIAN_FRONTEND=noninteractive \
      apt-get install -y -q --no-install-recommends "${missing[@]}"; } >"$log" 2>&1 ||
    skip "could not install ${missing[*]} (see $log)"
fi

# ---- Xvfb on a free display; -fbdir keeps the screen in DIR/Xvfb_screen0 (XWD), and -nocursor
# keeps the pointer out of it ----
work=$(mktemp -d)
xvfb=""
cleanup() {
  if [ -n "$xvfb" ]; then kill "$xvfb" 2>/dev/null || true; wait "$xvfb" 2>/dev/null || true; fi
  rm -rf "$work"
}
trap cleanup EXIT
mkdir -p "$work/fb" "$work/runtime"
chmod 700 "$work/runtime"
Xvfb -displayfd 3 -screen 0 1280x1024x24 -nocursor -fbdir "$work/fb" -nolisten tcp 3>"$work/display" 2>"$work/xvfb.log" &
xvfb=$!
for _ in $(seq 1 100); do
  [ -s "$work/display" ] && break
  kill -0 "$xvfb" 2>/dev/null || break
  sleep 0.1
done
[ -s "$work/display" ] || skip "Xvfb did not start: $(tail -n 3 "$work/xvfb.log" | tr '\n' ' ')"
export DISPLAY=":$(head -n 1 "$work/display")"
export DEFOCUS_PREVIEW="$preview" DEFOCUS_XVFB_SCREEN="$work/fb/Xvfb_screen0" XDG_RUNTIME_DIR="$work/runtime"
say "Xvfb on $DISPLAY"
"$probe"
