#!/usr/bin/python3
"""Global image speed of a recorded frame sequence, by phase correlation.

For each pair of consecutive frames of <folder>/images.txt (`t path`), the
translation that best aligns them (peak of the normalised cross-power
spectrum, integer pixels, Hann window) divided by the time between them:
a whole-image speed in px/s, for recordings without ground truth (the ECD
boxes_6dof frame slice). Under rotation and small depth range it is the
median flow; with strong parallax it is the dominant layer's.

    scripts/frame_shift_speed.py tests/data/ecd/boxes_6dof_frames
"""
import sys

import numpy as np
from PIL import Image


def shift(a: np.ndarray, b: np.ndarray) -> float:
    window = np.outer(np.hanning(a.shape[0]), np.hanning(a.shape[1]))
    fa = np.fft.fft2((a - a.mean()) * window)
    fb = np.fft.fft2((b - b.mean()) * window)
    cross = fa * np.conj(fb)
    corr = np.fft.ifft2(cross / (np.abs(cross) + 1e-9)).real
    dy, dx = np.unravel_index(np.argmax(corr), corr.shape)
    dy = dy - a.shape[0] if dy > a.shape[0] // 2 else dy
    dx = dx - a.shape[1] if dx > a.shape[1] // 2 else dx
    return float(np.hypot(dx, dy))


def main() -> int:
    if len(sys.argv) != 2:
        print(__doc__, file=sys.stderr)
        return 1
    folder = sys.argv[1]
    rows = [line.split() for line in open(f"{folder}/images.txt") if line.strip() and not line.startswith("#")]
    frames = [(float(t), np.asarray(Image.open(f"{folder}/{p}").convert("L"), dtype=np.float64)) for t, p in rows]
    print("t_s px_per_s")
    for (t0, a), (t1, b) in zip(frames, frames[1:]):
        print(f"{0.5 * (t0 + t1):.3f} {shift(a, b) / (t1 - t0):.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
