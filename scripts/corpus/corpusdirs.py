# SPDX-License-Identifier: LGPL-2.1-or-later
# The scene folders a corpus script is given: a scene folder (scene.json) as it is, a corpus
# folder as its scene folders in name order (anchors.py, turn.py).
import os
import sys


def scene_dirs(path, program):
    """The scene folders of `path`; exits with `program`'s error line where there are none."""
    if not os.path.isdir(path):
        sys.exit(f"{program}: error: {path} is not a folder")
    if os.path.isfile(os.path.join(path, "scene.json")):
        return [path]
    found = sorted(os.path.join(path, d) for d in os.listdir(path)
                   if os.path.isfile(os.path.join(path, d, "scene.json")))
    if not found:
        sys.exit(f"{program}: error: {path} is neither a scene folder (scene.json) nor a corpus of them")
    return found
