#!/usr/bin/python3
"""Measures the DAVIS240C APS parameters that the Event-Camera Dataset frames
show (issue 17): white level and its fixed-pattern spread, temporal noise,
the photon-transfer gain, read noise and the black pile. Prints one line per
figure; the presets in simulator/presets/aps_davis240c.yaml quote them.

  /usr/bin/python3 scripts/measure_aps_ecd.py tests/data/ecd/boxes_6dof_frames

Frames are the 8-bit PNGs named in images.txt (Mueggler et al., IJRR 2017,
CC BY-NC-SA 3.0). Definitions:
  white level      mean DN of pixels >= 108 (the pile below the 8-bit ceiling)
  white FPN        spatial sigma of per-pixel means over frames where the pixel is >= 108
                   (pixels saturated in >= 30 of the frames)
  white noise      rms temporal sigma of the same pixels
  photon transfer  consecutive frame pairs with median |difference| <= 1 DN (camera
                   nearly still); pixels with local gradient < 4 DN in both frames;
                   var(difference)/2 against the mean in 10-DN bins from 5 to 95 DN; a
                   least-squares line var = g * DN + s0: g in DN per electron, s0 the
                   read-noise variance plus 1/12 DN^2 of quantisation
  black pile       fraction of pixels at 0 DN; density per DN over 1-8 DN; their
                   ratio is the dark offset below 0 if the scene's radiance density
                   is flat near black
"""
import sys

import numpy as np
from PIL import Image


def load(folder):
    names = [line.split()[1] for line in open(folder + "/images.txt") if line.strip() and not line.startswith("#")]
    return np.stack([np.array(Image.open(folder + "/" + n)) for n in names]).astype(float)


def gradient(f):
    g = np.zeros_like(f)
    g[:, 1:-1] = np.abs(f[:, 2:] - f[:, :-2])
    g[1:-1, :] = np.maximum(g[1:-1, :], np.abs(f[2:, :] - f[:-2, :]))
    return g


def main(folder):
    a = load(folder)
    print(f"frames {a.shape[0]}, {a.shape[2]} x {a.shape[1]} px")
    white = a >= 108
    vals = np.where(white, a, np.nan)
    keep = white.sum(0) >= 30
    mu = np.nanmean(vals[:, keep], 0)
    sd = np.nanstd(vals[:, keep], 0, ddof=1)
    print(f"white level {a[white].mean():.2f} DN (pixels >= 108)")
    print(f"white FPN sigma {mu.std():.2f} DN over {keep.sum()} pixels; white temporal sigma {np.sqrt(np.mean(sd**2)):.2f} DN")
    means, diffs = [], []
    for k in range(a.shape[0] - 1):
        f0, f1 = a[k], a[k + 1]
        if np.median(np.abs(f1 - f0)) > 1:
            continue
        m = 0.5 * (f0 + f1)
        ok = (gradient(f0) < 4) & (gradient(f1) < 4) & (m > 5) & (m < 95)
        means.append(m[ok])
        diffs.append((f1 - f0)[ok])
    m, d = np.concatenate(means), np.concatenate(diffs)
    xs, ys = [], []
    for lo in range(5, 95, 10):
        s = (m >= lo) & (m < lo + 10)
        if s.sum() > 200:
            xs.append(m[s].mean())
            ys.append(d[s].var() / 2)
    g, s0 = np.polyfit(xs, ys, 1)
    zero = (a == 0).mean()
    density = np.mean([(a == v).mean() for v in range(1, 9)])
    offset = -zero / density
    white = a[white].mean()
    # Shot noise grows with the signal above the offset: var = g (DN - offset) + read^2 + 1/12.
    read = np.sqrt(max(s0 - 1 / 12 + g * offset, 0))
    print(f"photon transfer: {len(means)} still pairs, {len(m)} pixels; var = {g:.4f} * DN + {s0:.3f}")
    print(f"black pile {100 * zero:.2f} % at 0 DN; density {100 * density:.3f} %/DN over 1-8 DN; "
          f"implied dark offset {offset:.1f} DN")
    print(f"gain {g:.4f} DN/e- ({1 / g:.1f} e-/DN); swing {white - offset:.1f} DN = full well {(white - offset) / g:.0f} e-; "
          f"read noise {read:.2f} DN = {read / g:.0f} e-")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "tests/data/ecd/boxes_6dof_frames")
