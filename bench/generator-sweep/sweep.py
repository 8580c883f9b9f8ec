#!/usr/bin/env python3
"""Accuracy sweep on the product's own generator sails (`sailshape simulate`):
per seed, each corner's error (cm) and each section parameter that misses issue
2's target, then the worst of each and how many runs missed.

usage: sweep.py TYPE NOISE_MM FIRST_SEED LAST_SEED POINTS [scene] > OUT.txt
  TYPE       main, square-top, jib or gennaker
  env SAILSHAPE  the binary that analyses (default build/cli/sailshape); the clouds
                 and their truth are always written by build/cli/sailshape
  env DIR        where clouds and results go (default /tmp/generator-sweep)
Runs two analyses at a time. Compare two outputs with compare.py."""
import hashlib, json, math, os, subprocess, sys
from concurrent.futures import ThreadPoolExecutor

here = os.path.dirname(os.path.abspath(__file__))
writer = os.path.join(here, '..', '..', 'build', 'cli', 'sailshape')
kind, noise, first, last, points = sys.argv[1], float(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5])
scene = sys.argv[6:7] == ['scene']
exe = os.environ.get('SAILSHAPE', writer)
out_dir = os.environ.get('DIR', '/tmp/generator-sweep')
os.makedirs(out_dir, exist_ok=True)
tag = os.path.basename(exe) + '_' + hashlib.md5(os.path.realpath(exe).encode()).hexdigest()[:6]
targets = (dict(camber_pct=0.1, draft_pct=1, twist_deg=0.1, entry_deg=1, exit_deg=1) if noise == 0 else
           dict(camber_pct=0.3, draft_pct=2, twist_deg=0.3, entry_deg=2.5, exit_deg=2.5))


def run(seed):
    stem = '%s/%s_%g_%d_%d%s' % (out_dir, kind, noise, seed, points, '_scene' if scene else '')
    if not os.path.exists(stem + '_truth.json'):
        subprocess.run([writer, 'simulate', '--type', kind, '--seed', str(seed), '--noise-mm', str(noise),
                        '--points', str(points), '--out', stem + '.ply', '--truth', stem + '_truth.json'] +
                       (['--scene'] if scene else []), check=True, capture_output=True)
    result = '%s_%s.json' % (stem, tag)
    r = subprocess.run([exe, 'analyze', stem + '.ply', '--json', result, '-q'], capture_output=True, text=True)
    if r.returncode:
        return seed, None, r.stderr.strip()
    return seed, json.load(open(result)), json.load(open(stem + '_truth.json'))


worst, missed = {}, {}
with ThreadPoolExecutor(2) as pool:
    for seed, got, truth in pool.map(run, range(first, last + 1)):
        if got is None:
            print(seed, 'FAILED', truth)
            continue
        line = []
        for c in ('tack', 'clew', 'head', 'peak'):
            if c not in truth:
                continue
            e = 100 * math.dist(truth[c], got['sail']['corners'][c]) if c in got['sail']['corners'] else 999
            line.append('%s %.2f' % (c, e))
            worst[c] = max(worst.get(c, 0), e)
            missed[c] = missed.get(c, 0) + (e > 3)
        for t, s in zip(truth['sections'], got['sections']):
            for key, limit in targets.items():
                e = abs(t[key] - s[key]) if s.get(key) is not None else 99
                name = '%s@%.2f' % (key, t['fraction'])
                worst[name] = max(worst.get(name, 0), e)
                missed[name] = missed.get(name, 0) + (e > limit)
                if e > limit:
                    line.append('%s %.3f!' % (name, e))
        print(seed, ' '.join(line), flush=True)
print('WORST', ' '.join('%s %.3f (%d over)' % (k, v, missed[k]) for k, v in worst.items()))
