#!/usr/bin/python3
"""Isolated events of a sequence folder's events.txt (`t x y p`): events with
no other event in their 3x3 neighbourhood within +-10 ms (the definition of
`evio stats`); prints their count, rate per pixel and ON fraction, which
tells shot-like noise (both polarities) from leak noise (ON only).

    scripts/isolated_events.py tests/data/ecd/shapes_rotation_events
"""
import sys
from collections import defaultdict

import numpy as np

if len(sys.argv) != 2:
    print(__doc__, file=sys.stderr)
    sys.exit(1)
d = np.loadtxt(sys.argv[1] + '/events.txt', comments='#'); t = d[:,0]; x = d[:,1].astype(int); y = d[:,2].astype(int); p = d[:,3]
W, H = 240, 180
iso = np.ones(len(t), bool)
times = defaultdict(list)
for i in range(len(t)): times[(x[i],y[i])].append(t[i])
for k in times: times[k] = np.array(times[k])
for i in range(len(t)):
    for dx in (-1,0,1):
        for dy in (-1,0,1):
            a = times.get((x[i]+dx, y[i]+dy))
            if a is None: continue
            j = np.searchsorted(a, t[i]-0.01); k2 = np.searchsorted(a, t[i]+0.01, 'right')
            n = k2 - j - (1 if dx==0 and dy==0 else 0)
            if n > 0: iso[i] = False; break
        if not iso[i]: break
dur = t[-1]-t[0]
print('isolated', iso.sum(), 'rate Hz/px', iso.sum()/dur/(W*H), 'ON frac of isolated', p[iso].mean(), 'ON frac of all', p.mean())
