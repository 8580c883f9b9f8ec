#!/usr/bin/env python3
"""Each run in DIR against its truth: corners (cm) against the generator's exact
corners, section parameters against `design show` on the exact surface, per run
the worst of each and which miss issue 2's targets (clean / 4 mm noise), then per
sail kind and noise the worst and the count over target.
usage: compare.py DIR"""
import glob, json, math, os, sys
tag = sys.argv[1]
rows = {}
def dist(a, b): return math.sqrt(sum((a[i]-b[i])**2 for i in range(3)))
tgt = {'clean': dict(camber_pct=0.1, draft_pct=1, twist_deg=0.1, entry_deg=1, exit_deg=1, corner=3),
       'noisy': dict(camber_pct=0.3, draft_pct=2, twist_deg=0.3, entry_deg=2.5, exit_deg=2.5, corner=3)}
agg = {}
for tf in sorted(glob.glob(os.path.join(tag, '*_truth.json'))):
    p = tf[:-11]; name = os.path.basename(p)
    kind, seed, z = name.split('_')
    grp = (kind, 'clean' if float(z) == 0 else 'noisy')
    try:
        t = json.load(open(tf)); d = json.load(open(p + '_d.json')); a = json.load(open(p + '_a.json'))
    except Exception as e:
        print('MISSING', name, e); continue
    g = agg.setdefault(grp, {})
    worst = {}
    for c, v in t['corners'].items():
        e = dist(v, a['sail']['corners'][c]) * 100 if c in a['sail'].get('corners', {}) else 999
        g.setdefault('corner', []).append(e); worst['corner'] = max(worst.get('corner', 0), e)
    for sd, sa in zip(d['sections'], a['sections']):
        for key in ('camber_pct', 'draft_pct', 'twist_deg', 'entry_deg', 'exit_deg'):
            e = abs(sd[key] - sa[key]) if sa[key] is not None else 99; g.setdefault(key, []).append(e); worst[key] = max(worst.get(key, 0), e)
    flag = [k for k, v in worst.items() if v > tgt[grp[1]][k]]
    print('%-16s' % name, ' '.join('%s %.2f' % (k[:6], v) for k, v in worst.items()), ('MISS ' + ','.join(flag)) if flag else '')
print()
for grp, g in sorted(agg.items()):
    print(grp, ' '.join('%s max %.2f (%d/%d>)' % (k[:6], max(v), sum(1 for x in v if x > tgt[grp[1]][k]), len(v)) for k, v in g.items()))
