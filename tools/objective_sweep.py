"""Summarizes tools/objective-sweep.sh OUT: per seed and speed weight, the held-out S_B-S_D
distances (compare --holdout 1 and 2, all persons), and the replayed takes 5-8 (speed
correlation, extra jumps, fast starts); then the means over the seeds per weight."""
import re, glob, os, statistics as st
import sys
root = sys.argv[1]
rows = {}
for seed in (1, 2, 3):
    for w in ("0", "0.02", "0.05", "0.1", "0.2"):
        tag = f"s{seed}-w{w}"
        r = {}
        for h in (1, 2):
            p = f"{root}/hc-{tag}-h{h}/summary.md"
            if not os.path.exists(p): continue
            md = open(p).read()
            m = re.search(r"\| \*\*all\*\* \| [^|]+\| ([\d.]+)[^|]*\| ([\d.]+)[^|]*\| ([\d.]+)[^|]*\| ([\d.]+)[^|]*\| ([\d.]+)[^|]*\|", md)
            if m: r[f"h{h}"] = [float(x) for x in m.groups()]  # neutral, sa, sb, sc, sd
            o = re.search(r"Own vector best on its own held-out takes: (\d) of 3", md)
            if o: r[f"own{h}"] = int(o.group(1))
        p = f"{root}/st-{tag}.log"
        if os.path.exists(p):
            txt = open(p).read()
            m = re.search(r"(\d+) reaches: (\d+) with extra jumps, (\d+) not reached .* (\d+) start >0.3 m/s off; speed correlation with the capture mean ([\d.-]+), min ([\d.-]+)", txt)
            if m:
                n, jumps, notr, fast, mean, mn = m.groups()
                r["st"] = (float(mean), float(mn), int(jumps), int(fast), int(n), int(notr))
        rows[(seed, w)] = r
print("seed w   | holdout1 S_B S_C S_D (mm) own | holdout2 S_B S_C S_D own | takes 5-8 (fit 1-4, S_D)")
for (seed, w), r in rows.items():
    h1 = r.get("h1"); h2 = r.get("h2"); s = r.get("st")
    f = lambda h: " ".join(f"{x:6.2f}" for x in h[2:]) if h else "-"
    print(f"{seed} {w:5} | {f(h1)} {r.get('own1','-')} | {f(h2)} {r.get('own2','-')} | " + (f"r {s[0]:.2f}/{s[1]:.2f} jumps {s[2]} fast-start {s[3]}/{s[4]} not reached {s[5]}" if s else "-"))
print()
for w in ("0", "0.02", "0.05", "0.1", "0.2"):
    got = [rows[(s, w)] for s in (1, 2, 3) if "h1" in rows[(s, w)] and "h2" in rows[(s, w)] and "st" in rows[(s, w)]]
    if not got: continue
    m = lambda k, i: st.fmean(g[k][i] for g in got)
    print(f"w {w:5}: seeds {len(got)}: holdout1 S_D {m('h1',4):.2f} best(S_B..S_D) {st.fmean(min(g['h1'][2:]) for g in got):.2f}; holdout2 S_D {m('h2',4):.2f}; "
          f"takes 5-8 speed r {st.fmean(g['st'][0] for g in got):.3f} (min {min(g['st'][1] for g in got):.2f}), extra jumps {sum(g['st'][2] for g in got)}, start >0.3 m/s off {sum(g['st'][3] for g in got)}/{sum(g['st'][4] for g in got)}")
