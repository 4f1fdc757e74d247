#!/usr/bin/python3
# SPDX-License-Identifier: LGPL-2.1-or-later
# The CoC that scripts/corpus/anchors.py gives the tools it measures (GEGL's lens-blur takes it as
# its blur radius per pixel) must be the CoC of the truth's camera, as the filter computes it.
# Defect caught: the anchors blurred with the image-distance factor f / (S1 - f) where the renders'
# camera ("fieldOfView": "focal-length") has f / S1, so GEGL blurred 0.7-5 % too much and measured
# worse than it is. Needs only Python 3 (no NumPy).
#   tests/anchors-coc-test.py [REPOSITORY_ROOT]
import json
import pathlib
import sys
import unittest

ROOT = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parents[1])
sys.path.insert(0, str(ROOT / "scripts" / "corpus"))
from thinlens import coc_px  # noqa: E402


def scenes():
    found = [ROOT / "data" / "blender_spheres"] + sorted(p.parent for p in (ROOT / "data" / "corpus").glob("*/scene.json"))
    return [(p.name, json.loads((p / "scene.json").read_text())["lens"]) for p in found]


def focal_length_coc_px(depth_m, lens, width):
    """Written out apart from thinlens.py: the sensor at f (Cycles' camera), the blur on the focus
    plane A (S2 - S1) / S2 magnified by f / S1; c = f^2 (S2 - S1) / (N S1 S2), in millimetres."""
    f, n = lens["focalLengthMm"], lens["fNumber"]
    s1, s2 = lens["focusM"] * 1000.0, depth_m * 1000.0
    return f * f * (s2 - s1) / (n * s1 * s2) * width / lens["sensorWidthMm"]


class AnchorCoc(unittest.TestCase):
    def test_the_corpus_is_there(self):
        self.assertGreaterEqual(len(scenes()), 2, f"no scene.json under {ROOT / 'data'}")

    def test_the_bundled_scene_as_the_filter_measures_it(self):
        # The bundled spheres scene's depth runs from 1.43 to 30 m; the filter's CoC there (the
        # benchmark, docs/accuracy.md) runs from -45.8 to +15.3 px. The image-distance factor
        # gives -46.6 and +15.6 (data/README.md, tests/LensTest.cpp).
        lens = dict(scenes())["blender_spheres"]
        self.assertEqual(lens["fieldOfView"], "focal-length")
        self.assertAlmostEqual(coc_px(1.43, lens, 640), -45.8, delta=0.1)
        self.assertAlmostEqual(coc_px(30.0, lens, 640), 15.3, delta=0.1)

    def test_every_scene_gets_its_cameras_coc(self):
        for name, lens in scenes():
            s1 = lens["focusM"]
            for depth in (0.3, 0.5 * s1, s1, 2.0 * s1, 100.0):
                with self.subTest(scene=name, depth_m=depth):
                    expected = focal_length_coc_px(depth, lens, 640)
                    self.assertAlmostEqual(coc_px(depth, lens, 640), expected, delta=1e-9 * (1.0 + abs(expected)))

    def test_a_real_lens_sees_the_same_blur_s_over_s_minus_f_larger(self):
        # The other convention (filter/Lens.cpp, FieldOfView::ImageDistance) for camera footage.
        for name, lens in scenes():
            image = dict(lens, fieldOfView="image-distance")
            s1, f = lens["focusM"], lens["focalLengthMm"] / 1000.0
            with self.subTest(scene=name):
                self.assertAlmostEqual(coc_px(2.0 * s1, image, 640) * (s1 - f) / s1, coc_px(2.0 * s1, lens, 640),
                                       delta=1e-9)

    def test_an_unknown_convention_is_refused(self):
        with self.assertRaises(ValueError):
            coc_px(2.0, dict(scenes()[0][1], fieldOfView="sensor"), 640)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1])
