#!/usr/bin/env python3
"""A sail generator written apart from analysis/sail_generator: sails built from
horizontal stripes with a cubic mean line (main, sq = square top, genn =
gennaker-like, jib = headsail on a raked forestay), their size, camber, draft, twist and luff sag drawn per seed.
Writes OUT_design.ply (the exact surface, 400 x 200 cells: the truth's sections
come from `sailshape design show` on it), OUT_truth.json (exact corners) and
OUT.xyz (samples spread uniformly by area, Gaussian noise).

usage: gen.py main|sq|genn|jib SEED POINTS NOISE_MM OUT [ray] [scene] [holes] [scale=S] [lines=M]
  ray      noise along the ray from a scanner position instead of isotropic
  scene    add a mast beside the luff, a boom under the foot and a deck
  holes    cut 2-5 holes (3-6 % of the stripe and chord parameters) out of the samples
  scale=S  every length times S (0.2: a 1:5 wind-tunnel model)
  lines=M  keep only samples in thin bands M metres apart at 10 m from the scanner
"""
import bisect, math, random, sys, json
kind, seed, npts, noise_mm, out = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]), sys.argv[5]
opts = sys.argv[6:]
scene = 'scene' in opts; ray = 'ray' in opts; holes = 'holes' in opts
LINES = float([o for o in opts if o.startswith('lines=')][0][6:]) if any(o.startswith('lines=') for o in opts) else 0.0
SC = float([o for o in opts if o.startswith('scale=')][0][6:]) if any(o.startswith('scale=') for o in opts) else 1.0
R = random.Random(seed * 7919 + {'main': 1, 'genn': 2, 'sq': 3, 'jib': 4}[kind])
U = lambda a, b: R.uniform(a, b)
if kind == 'main':
    H = U(7, 14); F = H * U(0.3, 0.45); tack = (U(-0.3, 0.3), 0.0, U(0.4, 1.5)); rake = U(-0.06, 0.02) * H
    sag = U(-0.01, 0.01) * H; ch = 0.0
    cam = (U(0.06, 0.12), U(0.08, 0.15), U(0.06, 0.13)); drf = (U(-0.6, 0.3), U(-0.6, 0.3), U(-0.6, 0.3))
    tw0 = U(2, 10); dtw = U(5, 20); side = R.choice([-1, 1]); rise = U(0.0, 0.15) * F
elif kind == 'sq':
    H = U(7, 14); F = H * U(0.3, 0.45); tack = (U(-0.3, 0.3), 0.0, U(0.4, 1.5)); rake = U(-0.06, 0.02) * H
    sag = U(-0.01, 0.01) * H; ch = F * U(0.25, 0.45)
    cam = (U(0.06, 0.12), U(0.08, 0.15), U(0.06, 0.13)); drf = (U(-0.6, 0.3), U(-0.6, 0.3), U(-0.6, 0.3))
    tw0 = U(2, 10); dtw = U(5, 20); side = R.choice([-1, 1]); rise = U(0.0, 0.15) * F
elif kind == 'jib':
    # forestay from the bow raked 14-22 deg aft, sagging to leeward; the clew low or high
    H = U(8, 14); F = H * U(0.3, 0.6); tack = (U(2.5, 4.5), 0.0, U(0.3, 1.0)); rake = -math.tan(math.radians(U(14, 22))) * H
    sag = U(0.005, 0.02) * H; ch = 0.0
    cam = (U(0.08, 0.14), U(0.09, 0.16), U(0.07, 0.14)); drf = (U(-0.5, 0.3), U(-0.5, 0.3), U(-0.5, 0.3))
    tw0 = U(3, 10); dtw = U(5, 20); side = R.choice([-1, 1]); rise = U(-0.05, 0.25) * F
else:
    H = U(10, 16); F = H * U(0.45, 0.65); tack = (U(1.0, 3.0), 0.0, U(0.3, 1.0)); rake = U(-0.15, -0.05) * H
    sag = U(0.04, 0.09) * H; ch = 0.0
    cam = (U(0.12, 0.2), U(0.15, 0.25), U(0.12, 0.2)); drf = (U(-0.5, 0.2), U(-0.5, 0.2), U(-0.5, 0.2))
    tw0 = U(10, 25); dtw = U(10, 30); side = R.choice([-1, 1]); rise = U(0.05, 0.25) * F
H *= SC; F *= SC; tack = tuple(x * SC for x in tack); rake *= SC; sag *= SC; ch *= SC; rise *= SC
def interp(v, t):  # smooth quadratic through foot, mid, head
    a, b, c = v
    return a * (1 - t) * (1 - 2 * t) + 4 * b * t * (1 - t) + c * t * (2 * t - 1)
def luff(t):
    # straight tack->head plus sideways/forward sag (bulges to the camber side)
    x = tack[0] + rake * t + 0.3 * sag * 4 * t * (1 - t)
    y = side * sag * 4 * t * (1 - t)
    z = tack[2] + H * t
    return (x, y, z)
def chord(t):
    return F * (1 - t) + ch * t
def point(t, u):
    L = luff(t)
    c = chord(t)
    tw = math.radians(tw0 + dtw * t ** 1.2)
    d = (-math.cos(tw), -side * math.sin(tw), 0.0)  # luff -> leech direction, horizontal
    # leech rises above the luff point at the foot (clew higher than tack), fading to the head
    dz = rise * (1 - t) / max(c, 1e-9) if c > 1e-9 else 0.0
    n = (-d[1], d[0], 0.0)  # horizontal, perpendicular to the chord
    if n[1] * side < 0: n = (-n[0], -n[1], 0.0)  # camber bulges to the side
    D = interp(cam, t); k = interp(drf, t)
    f = u * (1 - u) * (1 + k * u) * 4 / (1 + max(k, 0) * 0.5 + 1e-12)
    x = L[0] + c * u * d[0] + c * D * f * n[0]
    y = L[1] + c * u * d[1] + c * D * f * n[1]
    z = L[2] + c * u * dz
    return (x, y, z)
NT, NU = 400, 200
grid = [[point(i / NT, j / NU) for j in range(NU + 1)] for i in range(NT + 1)]
tris = []
for i in range(NT):
    for j in range(NU):
        a, b, c2, d2 = (i, j), (i, j + 1), (i + 1, j), (i + 1, j + 1)
        tris.append((a, b, d2)); tris.append((a, d2, c2))
def P(ij): return grid[ij[0]][ij[1]]
def area(tr):
    A, B, C = P(tr[0]), P(tr[1]), P(tr[2])
    u = [B[k] - A[k] for k in range(3)]; v = [C[k] - A[k] for k in range(3)]
    cx = u[1] * v[2] - u[2] * v[1]; cy = u[2] * v[0] - u[0] * v[2]; cz = u[0] * v[1] - u[1] * v[0]
    return 0.5 * math.sqrt(cx * cx + cy * cy + cz * cz)
areas = [area(t) for t in tris]
# mesh (design truth): vertex ids; the head row of a triangular sail collapses
vid = {}; verts = []
def V(ij):
    key = ij if (kind == 'sq' or ij[0] < NT) else (NT, 0)
    if key not in vid: vid[key] = len(verts); verts.append(P(key))
    return vid[key]
faces = []
for t in tris:
    f = [V(x) for x in t]
    if len(set(f)) == 3: faces.append(f)
with open(out + '_design.ply', 'w') as fo:
    fo.write('ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n'
             'element face %d\nproperty list uchar int vertex_indices\nend_header\n' % (len(verts), len(faces)))
    for v in verts: fo.write('%.6f %.6f %.6f\n' % v)
    for f in faces: fo.write('3 %d %d %d\n' % tuple(f))
# cumulative areas for sampling
cum = []; s = 0
for a in areas: s += a; cum.append(s)
sig = noise_mm / 1000.0
RS = random.Random(seed * 31 + 5)
view = (-F * 0.5 + RS.uniform(-2, 2), -side * RS.uniform(6, 10), tack[2] + H * RS.uniform(0.3, 0.6))
hole_list = [(RS.uniform(0.15, 0.85), RS.uniform(0.15, 0.85), RS.uniform(0.03, 0.06)) for _ in range(RS.randint(2, 5))] if holes else []
def noisy(p):
    if ray:
        d = [p[m] - view[m] for m in range(3)]; n = math.sqrt(sum(x * x for x in d))
        e = R.gauss(0, sig); return [p[m] + e * d[m] / n for m in range(3)]
    return [p[m] + R.gauss(0, sig) for m in range(3)]
with open(out + '.xyz', 'w') as fo:
    written = 0
    while written < npts:
        k = bisect.bisect_left(cum, R.random() * s)
        tr = tris[k]
        A, B, C = (P(x) for x in tr)
        r1, r2 = R.random(), R.random()
        if r1 + r2 > 1: r1, r2 = 1 - r1, 1 - r2
        if hole_list:
            ti = (tr[0][0] + r1 * (tr[1][0] - tr[0][0]) + r2 * (tr[2][0] - tr[0][0])) / NT
            uj = (tr[0][1] + r1 * (tr[1][1] - tr[0][1]) + r2 * (tr[2][1] - tr[0][1])) / NU
            if any((ti - a) ** 2 + (uj - b) ** 2 < r * r for a, b, r in hole_list): continue
        p = [A[m] + r1 * (B[m] - A[m]) + r2 * (C[m] - A[m]) for m in range(3)]
        if LINES > 0:
            # scan lines: vertical planes through the scanner, LINES metres apart at 10 m; keep a thin band
            az = math.atan2(p[1] - view[1], p[0] - view[0]) * 10.0 / LINES
            if abs(az - round(az)) > 0.04: continue
        fo.write('%.5f %.5f %.5f\n' % tuple(noisy(p))); written += 1
    if scene:
        dens = npts / s
        # mast: cylinder ahead of the luff, radius 6-9 cm, from the deck to above the head
        rm = RS.uniform(0.06, 0.09); gap = RS.uniform(0.02, 0.08); zdeck = tack[2] - RS.uniform(0.4, 0.9)
        def cyl(a, b, r, n, away):
            ax = [b[m] - a[m] for m in range(3)]; L = math.sqrt(sum(x * x for x in ax)); ax = [x / L for x in ax]
            u = [away[m] - ax[m] * sum(away[j] * ax[j] for j in range(3)) for m in range(3)]; nu = math.sqrt(sum(x * x for x in u)); u = [x / nu for x in u]
            v = [ax[1] * u[2] - ax[2] * u[1], ax[2] * u[0] - ax[0] * u[2], ax[0] * u[1] - ax[1] * u[0]]
            for _ in range(n):
                t = R.random() * L; ph = R.uniform(-math.pi / 2, math.pi / 2)  # the half the scanner sees
                q = [a[m] + ax[m] * t + r * (math.cos(ph) * u[m] + math.sin(ph) * v[m]) for m in range(3)]
                fo.write('%.5f %.5f %.5f\n' % tuple(noisy(q)))
        L0, L1 = luff(0), luff(1)
        d = [L1[m] - L0[m] for m in range(3)]; nd = math.sqrt(sum(x * x for x in d))
        # parallel to the luff's chord, its surface `gap` ahead of it all the way: a pole from
        # the deck straight up to above the head crossed a raked luff (a jib's, 14-22 deg)
        # 15-20 cm aft of the tack, through the sail
        c = rm + gap
        def onLuffLine(z): return [L0[m] + d[m] * (z - L0[2]) / d[2] for m in range(3)]
        base = onLuffLine(zdeck); top = onLuffLine(L1[2] + 0.5); base[0] += c; top[0] += c
        viewdir = [view[m] - (base[m] + top[m]) / 2 for m in range(3)]
        cyl(base, top, rm, int(dens * math.pi * rm * (top[2] - base[2])), viewdir)
        # boom: from the mast to past the clew, under the foot
        rb = RS.uniform(0.05, 0.08); cl = point(0, 1)
        b0 = [L0[0] - 0.0, L0[1], L0[2] - rb - RS.uniform(0.05, 0.15)]; b1 = [cl[0] - 0.3, cl[1], b0[2]]
        if kind in ('main', 'sq'): cyl(b0, b1, rb, int(dens * math.pi * rb * math.dist(b0, b1)), [view[m] - b0[m] for m in range(3)])
        # deck: 8 x 3 m patch at zdeck
        for _ in range(int(dens * 24 * 0.5)):
            q = [RS.uniform(-4, 4) + (L0[0] - F / 2), RS.uniform(-1.5, 1.5), zdeck]
            fo.write('%.5f %.5f %.5f\n' % tuple(noisy(q)))
corners = {'tack': luff(0), 'clew': point(0, 1), 'head': luff(1)}
if kind == 'sq': corners['peak'] = point(1, 1)
json.dump({'corners': corners, 'area_m2': s, 'kind': kind, 'H': H, 'F': F}, open(out + '_truth.json', 'w'))
print(out, 'area %.1f m2' % s)
