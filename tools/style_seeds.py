"""Summarizes tools/style-seeds.sh OUT: every run's `style` summary per person, then per
stopping rule, model and person over the seeds: the mean and least hand-speed correlation of
the person's full-body reaches with their captures, the hand-overs (and on how many seeds),
the mean peak error, and on how many seeds the test's bar holds (mean r >= 0.8, peak error
<= 0.1, no hand-over)."""
import collections
import glob
import json
import os
import re
import statistics as st
import sys

root = sys.argv[1]
runs = collections.defaultdict(list)
for path in sorted(glob.glob(os.path.join(root, "*-s*", "*.style.json"))):
    run = os.path.basename(os.path.dirname(path))
    m = re.fullmatch(r"(\w+)-(s[a-e])-s(\d+)", run)
    if not m:
        continue
    rule, model, seed = m.group(1), m.group(2), int(m.group(3))
    person = os.path.basename(path).split(".")[0]
    s = json.load(open(path))["summary"]
    row = (seed, s["params_correlation"], s["params_peak_error"], s["hand_overs"])
    runs[(rule, model, person)].append(row)
    print(f"{rule:8} {model} seed {seed} {person:8} r {row[1]:.3f} peak error {row[2]:.3f} hand-overs {row[3]}")
print()
print("rule     model person   seeds  mean r  least r  hand-overs (seeds)  mean peak error  bar held")
for (rule, model, person), rows in sorted(runs.items()):
    r = [x[1] for x in rows]
    ho = [x[3] for x in rows]
    bar = sum(1 for x in rows if x[1] >= 0.8 and x[2] <= 0.1 and x[3] == 0)
    print(f"{rule:8} {model}    {person:8} {len(rows):5}  {st.fmean(r):.3f}   {min(r):.3f}    "
          f"{sum(ho):3} ({sum(1 for h in ho if h):d})            {st.fmean(x[2] for x in rows):.3f}            {bar}/{len(rows)}")
