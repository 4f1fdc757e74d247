# SPDX-License-Identifier: LGPL-2.1-or-later
# The thin-lens CoC of a corpus scene's camera, as the filter computes it (filter/Lens.cpp,
# thinLensCocPixels()), for the scripts that drive other tools with it (anchors.py). Plain
# arithmetic: works on floats and on NumPy arrays alike; needs nothing beyond Python.


def coc_px(depth_m, lens, width):
    """Signed thin-lens CoC diameter in pixels (< 0 in front of the focus) of a point at depth_m
    metres, for a scene.json "lens" and an image width px wide.

    A point at depth S2 blurs into a disc of A (S2 - S1) / S2 on the focus plane at S1 (A = f / N,
    the aperture); a sensor at distance d behind the lens sees it d / S1 times as large. Renderers
    (Cycles, the corpus's camera: "fieldOfView": "focal-length") fit the sensor width at d = f;
    a real lens has its sensor at the image distance d = f S1 / (S1 - f) ("image-distance"),
    which makes the same blur S1 / (S1 - f) times as many pixels (1.7 % at 85 mm and 5 m, 5 % at
    24 mm and 0.5 m)."""
    f = lens["focalLengthMm"] / 1000.0
    aperture = f / lens["fNumber"]
    s1 = lens["focusM"]
    convention = lens["fieldOfView"]
    if convention == "focal-length":
        sensor_distance = f
    elif convention == "image-distance":
        sensor_distance = f * s1 / (s1 - f)
    else:
        raise ValueError(f'lens "fieldOfView": {convention!r} is neither "focal-length" nor "image-distance"')
    on_sensor_m = aperture * (depth_m - s1) / depth_m * sensor_distance / s1
    return on_sensor_m * width / (lens["sensorWidthMm"] / 1000.0)
