#!/usr/bin/python3
"""How many tracks a tracker keeps alive, and how they spread over the image,
at each frame of a sequence.

Input: a tracks file of `evio track` (id t x y, px) and the sequence's
images.txt (t path; only the times are read). At each frame time t a track
is live when its first point is at or before t and its last at or after t
(1 ns tolerance); it sits where its latest point at or before t is. The
image is cut into G × G equal cells (--grid, 4) of the --size W x H image; a
cell is covered when a live track sits in it (points outside the image go
to the nearest cell).

Printed: the number of frames; live tracks on the first frame, their mean
and minimum over the frames; covered cells, mean and minimum; the median
life of the tracks (last point − first point, s).

Usage: track_coverage.py TRACKS IMAGES_TXT --size 346x260 [--grid 4]
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "plots"))
from plot_tracks import load_tracks  # noqa: E402  (the project's reader of whitespace tables)

TIME_TOLERANCE_S = 1e-9


def frame_times(images_path):
    """The frame times of an images.txt (t path), s."""
    times = []
    try:
        with open(images_path) as f:
            for number, line in enumerate(f, 1):
                line = line.split("#", 1)[0].strip()
                if not line:
                    continue
                try:
                    times.append(float(line.split()[0]))
                except ValueError:
                    sys.exit(f"track_coverage.py: {images_path}:{number}: field t: not a number: {line.split()[0]!r}")
    except OSError as e:
        sys.exit(f"track_coverage.py: cannot read {images_path}: {e}")
    if not times:
        sys.exit(f"track_coverage.py: {images_path}: no frames")
    return np.array(times)


def positions_at(tracks, t):
    """[(x, y)] of the tracks live at t, each at its latest point at or
    before t. `tracks`: {id: rows (t, x, y) sorted by t}."""
    out = []
    for rows in tracks.values():
        if rows[0, 0] > t + TIME_TOLERANCE_S or rows[-1, 0] < t - TIME_TOLERANCE_S:
            continue
        k = np.searchsorted(rows[:, 0], t + TIME_TOLERANCE_S, side="right") - 1
        out.append(rows[k, 1:3])
    return out


def covered_cells(points, width, height, grid):
    """Cells of a grid × grid partition of the width × height image holding a point."""
    cells = set()
    for x, y in points:
        cx = min(max(int(x * grid // width), 0), grid - 1)
        cy = min(max(int(y * grid // height), 0), grid - 1)
        cells.add((cx, cy))
    return len(cells)


def by_track(rows):
    """{id: rows (t, x, y) sorted by t}."""
    tracks = {}
    for fid in np.unique(rows[:, 0]).astype(int):
        g = rows[rows[:, 0] == fid][:, 1:4]
        tracks[fid] = g[np.argsort(g[:, 0], kind="stable")]
    return tracks


def parse_size(text):
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        sys.exit(f"track_coverage.py: --size: expected WxH in pixels, got {text!r}")
    if w <= 0 or h <= 0:
        sys.exit(f"track_coverage.py: --size: expected positive WxH, got {text!r}")
    return w, h


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("tracks")
    p.add_argument("images")
    p.add_argument("--size", required=True, help="image size WxH, px")
    p.add_argument("--grid", type=int, default=4, help="cells per side (4)")
    a = p.parse_args()
    if a.grid < 1:
        sys.exit("track_coverage.py: --grid: expected at least 1")
    width, height = parse_size(a.size)
    tracks = by_track(load_tracks(a.tracks))
    times = frame_times(a.images)
    live, cells = [], []
    for t in times:
        points = positions_at(tracks, t)
        live.append(len(points))
        cells.append(covered_cells(points, width, height, a.grid))
    lives = [rows[-1, 0] - rows[0, 0] for rows in tracks.values()]
    print(f"frames {len(times)}")
    print(f"live tracks: first frame {live[0]}, mean {np.mean(live):.1f}, min {min(live)}")
    print(f"covered cells of {a.grid * a.grid}: mean {np.mean(cells):.1f}, min {min(cells)}")
    median_life = f"{np.median(lives):.3f}" if lives else "-"
    print(f"tracks {len(tracks)}, median life {median_life} s")


if __name__ == "__main__":
    main()
