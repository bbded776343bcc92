#!/usr/bin/python3
"""A one-picture preview of a sequence folder written by `evio simulate`.

Usage: plot_sequence_preview.py FOLDER [-o OUTPUT.png] [--frame K] [--window-ms 20]

Left: frame K of images/ with the ground-truth tracks visible at its stamp
(truth/tracks.txt, nearest sample in time) as green dots. Right: the events of
a window of --window-ms milliseconds ending at the frame's stamp (events.txt;
when missing, the event count per pixel is not drawn), ON white, OFF black,
on grey. Writes FOLDER/preview.png unless -o is given.
"""

import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read_list(path):
    rows = []
    with open(path) as f:
        for line in f:
            if line.strip() and not line.startswith("#"):
                t, p = line.split()
                rows.append((float(t), p))
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder")
    ap.add_argument("-o", "--output")
    ap.add_argument("--frame", type=int, default=0)
    ap.add_argument("--window-ms", type=float, default=20.0)
    a = ap.parse_args()
    images = os.path.join(a.folder, "images.txt")
    if not os.path.exists(images):
        sys.exit(f"plot_sequence_preview: {images} missing (frames off?)")
    frames = read_list(images)
    if not frames:
        sys.exit("plot_sequence_preview: no frames")
    k = min(max(a.frame, 0), len(frames) - 1)
    t_frame, rel = frames[k]
    img = plt.imread(os.path.join(a.folder, rel))
    h, w = img.shape[:2]

    fig, ax = plt.subplots(1, 2, figsize=(2 * w / 80, h / 80 + 0.4), dpi=80)
    ax[0].imshow(img, cmap="gray", vmin=0, vmax=1)
    tracks = os.path.join(a.folder, "truth", "tracks.txt")
    if os.path.exists(tracks):
        tr = np.loadtxt(tracks, comments="#", ndmin=2)
        if tr.size:
            ts = np.unique(tr[:, 1])
            t_near = ts[np.argmin(np.abs(ts - t_frame))]
            sel = tr[tr[:, 1] == t_near]
            ax[0].plot(sel[:, 2], sel[:, 3], ".", color="lime", ms=3)
    ax[0].set_title(f"frame {k} at {t_frame:.3f} s + truth tracks", fontsize=8)

    ev_img = np.full((h, w), 0.5)
    events = os.path.join(a.folder, "events.txt")
    if os.path.exists(events):
        t0 = t_frame - a.window_ms * 1e-3
        chunks = []
        with open(events) as f:
            for line in f:
                t = float(line.split(" ", 1)[0])
                if t > t_frame:
                    break
                if t >= t0:
                    chunks.append(line)
        if chunks:
            ev = np.loadtxt(chunks, ndmin=2)
            ev_img[ev[:, 2].astype(int), ev[:, 1].astype(int)] = ev[:, 3]
        ax[1].set_title(f"events {a.window_ms:g} ms before the frame ({len(chunks)})", fontsize=8)
    else:
        ax[1].set_title("events.txt not written", fontsize=8)
    ax[1].imshow(ev_img, cmap="gray", vmin=0, vmax=1)
    for x in ax:
        x.set_xticks([])
        x.set_yticks([])
        x.set_xlim(-0.5, w - 0.5)
        x.set_ylim(h - 0.5, -0.5)
    fig.tight_layout(pad=0.3)
    out = a.output or os.path.join(a.folder, "preview.png")
    fig.savefig(out)
    print(out)


if __name__ == "__main__":
    main()
