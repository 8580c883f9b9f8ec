#!/usr/bin/env python3
"""Two sweep.py outputs side by side: each corner's mean and worst error and the
runs over 3 cm, and every section parameter whose worst or count over target
differs.   usage: compare.py BEFORE.txt AFTER.txt"""
import re, sys


def load(path):
    seeds, worst = {}, {}
    for line in open(path):
        t = line.split()
        if t and t[0].isdigit():
            seeds[int(t[0])] = {t[i]: float(t[i + 1].rstrip('!')) for i in range(1, len(t) - 1, 2)}
        elif t and t[0] == 'WORST':
            for k, v, n in re.findall(r'(\S+) ([\d.]+) \((\d+) over\)', line):
                worst[k] = (float(v), int(n))
    return seeds, worst


(a, wa), (b, wb) = load(sys.argv[1]), load(sys.argv[2])
for c in ('tack', 'clew', 'head', 'peak'):
    va = [s[c] for s in a.values() if c in s]
    vb = [s[c] for s in b.values() if c in s]
    if va and vb:
        print('%-5s mean %.2f -> %.2f cm, worst %.2f -> %.2f, over 3 cm %d -> %d' % (
            c, sum(va) / len(va), sum(vb) / len(vb), max(va), max(vb),
            sum(x > 3 for x in va), sum(x > 3 for x in vb)))
for k in wa:
    if '@' in k and k in wb and wa[k] != wb[k]:
        print('%-18s worst %.3f -> %.3f, over target %d -> %d' % (k, wa[k][0], wb[k][0], wa[k][1], wb[k][1]))
