#!/usr/bin/env python3
# Samples on scan lines, as a 2D scanner on a turntable takes them without its
# angles: vertical planes through the scanner LINE_M apart at 10 m, a sample every
# ALONG_M of height on each; noise along the rays. Same sails as gen.py (run it
# first for the design and truth files).
# usage: genlines.py main|sq|genn SEED NOISE_MM OUT LINE_M ALONG_M
import sys, math, random, subprocess, json
kind, seed, noise, out, dl, da = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), sys.argv[4], float(sys.argv[5]), float(sys.argv[6])
import os
src = open(os.path.join(os.path.dirname(os.path.abspath(__file__)), 'gen.py')).read().split("NT, NU = 400, 200")[0]
src = src.replace("kind, seed, npts, noise_mm, out = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]), sys.argv[5]", "kind, seed, npts, noise_mm, out = %r, %d, 1000, %f, %r" % (kind, seed, noise, out)).replace("opts = sys.argv[6:]", "opts = []")
g = {}
exec(src, g)
point, side, H, F, tack = g['point'], g['side'], g['H'], g['F'], g['tack']
RS = random.Random(seed * 31 + 5)
view = (-F * 0.5 + RS.uniform(-2, 2), -side * RS.uniform(6, 10), tack[2] + H * RS.uniform(0.3, 0.6))
R = random.Random(seed)
def az(p): return math.atan2(p[1] - view[1], p[0] - view[0])
step = dl / 10.0
# azimuth range over the sail
azs = [az(point(t / 20, u / 20)) for t in range(21) for u in range(21)]
a0, a1 = min(azs), max(azs)
nt = int(H / da) + 1
pts = []
k = math.ceil(a0 / step)
while k * step <= a1:
    b = k * step; k += 1
    for i in range(nt + 1):
        t = i / nt
        # find u in [0,1] with az(point(t,u)) = b (az monotone in u along a chord line)
        lo, hi = 0.0, 1.0
        flo, fhi = az(point(t, lo)) - b, az(point(t, hi)) - b
        if flo * fhi > 0: continue
        for _ in range(30):
            mid = 0.5 * (lo + hi); fm = az(point(t, mid)) - b
            if (fm > 0) == (flo > 0): lo, flo = mid, fm
            else: hi = mid
        p = point(t, 0.5 * (lo + hi))
        d = [p[m] - view[m] for m in range(3)]; n = math.sqrt(sum(x * x for x in d))
        e = R.gauss(0, noise / 1000.0)
        pts.append([p[m] + e * d[m] / n for m in range(3)])
with open(out + '.xyz', 'w') as fo:
    for p in pts: fo.write('%.5f %.5f %.5f\n' % tuple(p))
print(len(pts), 'points')
