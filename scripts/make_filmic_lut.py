#!/usr/bin/env python3
"""Writes resources/ocio/luts/retile_filmic.spi1d, the tone curve of Retile's "Filmic" view.

The view maps scene-linear light through a log2 shaper (OCIO AllocationTransform lg2 over
[LOG2_MIN, LOG2_MAX]) and this 1D LUT, which gives display-linear light in [0, 1]; the sRGB
display colour space then encodes it. The curve is Narkowicz's published fit of the ACES filmic
response, after a 0.8 exposure so that middle grey (0.18) stays near 0.18 on screen, with a soft
shoulder that reaches white about six stops above middle grey.
"""
import os

LOG2_MIN = -12.473931188
LOG2_MAX = 12.526068812
LENGTH = 4096


def tone(x):
    x = max(x, 0.0) * 0.8
    a, b, c, d, e = 2.51, 0.03, 2.43, 0.59, 0.14
    return min(max((x * (a * x + b)) / (x * (c * x + d) + e), 0.0), 1.0)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    out = os.path.join(here, "..", "resources", "ocio", "luts", "retile_filmic.spi1d")
    lines = ["Version 1", "From 0.0 1.0", f"Length {LENGTH}", "Components 1", "{"]
    for i in range(LENGTH):
        t = i / (LENGTH - 1)
        x = 2.0 ** (LOG2_MIN + t * (LOG2_MAX - LOG2_MIN))
        lines.append(f"    {tone(x):.8f}")
    lines.append("}")
    with open(out, "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
