#!/usr/bin/python3
"""Draw feature tracks over a frame of a sequence.

Usage: plot_tracks.py SEQUENCE TRACKS.txt [--time T] [--window W] [-o OUTPUT.png]
                      [--truth TRUTH_TRACKS.txt]

Reads SEQUENCE/images.txt and the frame nearest to time T (seconds; default:
the middle frame), and TRACKS.txt (`id t x y`, as `evio track` writes).
Draws each track's samples within [T - W, T] (W default 0.2 s) as a line
ending in a dot at its latest position; with --truth, ground-truth tracks of
the same window are drawn thin and grey underneath. Writes OUTPUT (default
TRACKS.png beside TRACKS.txt).
"""

import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def load_table(path, names):
    """Rows of a whitespace table with the columns `names` (one string, the
    names separated by spaces; '#' starts a comment); exits with a clear
    message, named after the running script, on bad input."""
    script = os.path.basename(sys.argv[0]) or "evio"
    columns = len(names.split())
    try:
        data = np.loadtxt(path, comments="#", ndmin=2)
    except (OSError, ValueError) as e:
        sys.exit(f"{script}: cannot read {path}: {e}")
    if data.size == 0:
        return np.zeros((0, columns))
    if data.shape[1] != columns:
        sys.exit(f"{script}: {path}: expected {columns} columns '{names}', got {data.shape[1]}")
    return data


def load_tracks(path):
    """Rows (id, t, x, y) of an `evio track` file."""
    return load_table(path, "id t x y")


def load_frames(folder):
    path = os.path.join(folder, "images.txt")
    frames = []
    try:
        with open(path) as f:
            for line in f:
                line = line.strip()
                if not line or line.startswith("#"):
                    continue
                t, rel = line.split()[:2]
                frames.append((float(t), rel))
    except (OSError, ValueError) as e:
        sys.exit(f"plot_tracks: cannot read {path}: {e}")
    if not frames:
        sys.exit(f"plot_tracks: {path}: no frames")
    return frames


def draw(ax, tracks, t0, t1, style, dots):
    sel = tracks[(tracks[:, 1] >= t0) & (tracks[:, 1] <= t1)]
    for tid in np.unique(sel[:, 0]):
        tr = sel[sel[:, 0] == tid]
        tr = tr[np.argsort(tr[:, 1])]
        ax.plot(tr[:, 2], tr[:, 3], **style)
        if dots:
            ax.plot(tr[-1, 2], tr[-1, 3], "o", ms=3, color=style.get("color"))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("sequence")
    p.add_argument("tracks")
    p.add_argument("--time", type=float, default=None, help="seconds; default: middle frame")
    p.add_argument("--window", type=float, default=0.2, help="seconds of track history to draw")
    p.add_argument("--truth", default=None, help="ground-truth tracks (id t x y)")
    p.add_argument("-o", "--output", default=None)
    a = p.parse_args()

    frames = load_frames(a.sequence)
    times = np.array([t for t, _ in frames])
    t = a.time if a.time is not None else times[len(times) // 2]
    k = int(np.argmin(np.abs(times - t)))
    image = mpimg.imread(os.path.join(a.sequence, frames[k][1]))
    tracks = load_tracks(a.tracks)

    h, w = image.shape[:2]
    fig, ax = plt.subplots(figsize=(8, 8 * h / w))
    ax.imshow(image, cmap="gray", vmin=0, vmax=1 if image.dtype != np.uint8 else 255, extent=(-0.5, w - 0.5, h - 0.5, -0.5))
    if a.truth:
        draw(ax, load_tracks(a.truth), t - a.window, t, {"color": "0.7", "lw": 0.5}, False)
    draw(ax, tracks, t - a.window, t, {"lw": 1.2, "color": "tab:orange"}, True)
    ax.set_xlim(-0.5, w - 0.5)
    ax.set_ylim(h - 0.5, -0.5)
    ax.set_title(f"{os.path.basename(a.tracks)}: tracks in [{t - a.window:.3f}, {t:.3f}] s over frame {times[k]:.3f} s")
    ax.set_xlabel("u [px]")
    ax.set_ylabel("v [px]")
    out = a.output or os.path.splitext(a.tracks)[0] + ".png"
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print(out)


if __name__ == "__main__":
    main()
