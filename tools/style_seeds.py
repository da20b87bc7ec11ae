"""Summarizes tools/style-seeds.sh OUT: every run's `style` summary per person, then per
stopping rule, model and person over the seeds: the mean and least hand-speed correlation of
the person's full-body reaches with their captures, the hand-overs (and on how many seeds),
the mean peak error, on how many seeds the test's bar holds (mean r >= 0.8, peak error
<= 0.1, no hand-over) and on how many its whole check does: the bar, the synergy better than
the default profile on every take, and no speed jump the capture does not have (each main
reach, the character's resampled to the capture's frames, as
smooth_cli::held_out_full_body_reaches_keep_each_persons_style counts them; *active* may
have 3 more).

Usage: python3 tools/style_seeds.py OUT [KINERGY]   (KINERGY: the binary that reads the
speeds and segments, default target/release/kinergy; SHARED: the shared data folder)."""
import collections
import csv
import glob
import json
import os
import re
import statistics as st
import subprocess
import sys
import tempfile

root = sys.argv[1]
kinergy = sys.argv[2] if len(sys.argv) > 2 else "target/release/kinergy"
bandai = os.path.join(os.environ.get("SHARED", "../shared/data"), "bandai-raise-left")
scratch = tempfile.mkdtemp()


def jumps(v):
    """Frame-to-frame changes above 0.25 m/s and 4x the median change (kinergy_motion::jumps)."""
    d = [abs(b - a) for a, b in zip(v, v[1:])]
    if not d:
        return 0
    t = max(0.25, 4 * st.median(d))
    return sum(1 for x in d if x > t)


def main_reach(path):
    """The main reach's frames [onset, end) of the left arm, None when it has none."""
    o = json.loads(subprocess.run([kinergy, "segment", path, "--arm", "left", "--json"],
                                  capture_output=True, text=True, check=True).stdout)
    if o.get("main") is None:
        return None
    s = o["segments"][o["main"]]
    return s["onset"], s["end"]


def speeds(a, b):
    out = os.path.join(scratch, "speed.csv")
    subprocess.run([kinergy, "plot", "speed", a, b, "--relative", "--arm", "left", "-o",
                    os.path.join(scratch, "speed.svg"), "--csv", out, "-q"], check=True)
    series = collections.OrderedDict()
    for row in csv.DictReader(open(out)):
        series.setdefault(row["clip"], []).append(float(row["speed_m_s"]))
    return list(series.values())


def resample(v, n):
    if len(v) < 2 or n < 2:
        return v
    out = []
    for i in range(n):
        x = i * (len(v) - 1) / (n - 1)
        j = min(int(x), len(v) - 2)
        f = x - j
        out.append(v[j] * (1 - f) + v[j + 1] * f)
    return out


def extra_jumps(style_dir, person):
    """The takes whose full-body reach has more speed jumps than the test allows."""
    bad = []
    for reach in sorted(glob.glob(os.path.join(style_dir, "*.params.bvh"))):
        name = os.path.basename(reach).split(".")[0]
        capture = os.path.join(bandai, name + ".bvh")
        v = speeds(capture, reach)
        ours_reach = main_reach(reach)
        if ours_reach is None:
            bad.append(name + " (no main reach)")
            continue
        a, b = main_reach(capture)
        c, e = ours_reach
        captured = v[0][a:min(b, len(v[0]))]
        ours = resample(v[1][c:min(e, len(v[1]))], len(captured))
        allowed = jumps(captured) + (3 if person == "active" else 0)
        if jumps(ours) > allowed:
            bad.append(name)
    return bad


runs = collections.defaultdict(list)
for path in sorted(glob.glob(os.path.join(root, "*-s*", "*.style.json"))):
    run = os.path.basename(os.path.dirname(path))
    m = re.fullmatch(r"(\w+)-(s[a-e])-s(\d+)", run)
    if not m:
        continue
    rule, model, seed = m.group(1), m.group(2), int(m.group(3))
    person = os.path.basename(path).split(".")[0]
    s = json.load(open(path))["summary"]
    bad = extra_jumps(os.path.join(os.path.dirname(path), "style-" + person), person)
    whole = (s["params_correlation"] >= 0.8 and s["params_peak_error"] <= 0.1
             and s["hand_overs"] == 0 and not bad
             and s["params_better_correlation"] == s["captures"]
             and s["params_better_peak"] == s["captures"])
    row = (seed, s["params_correlation"], s["params_peak_error"], s["hand_overs"], bad, whole)
    runs[(rule, model, person)].append(row)
    print(f"{rule:8} {model} seed {seed} {person:8} r {row[1]:.3f} peak error {row[2]:.3f} "
          f"hand-overs {row[3]} extra jumps {','.join(bad) or '-'}")
print()
print("rule     model person   seeds  mean r  least r  hand-overs (seeds)  mean peak error  "
      "bar held  whole check")
for (rule, model, person), rows in sorted(runs.items()):
    r = [x[1] for x in rows]
    ho = [x[3] for x in rows]
    bar = sum(1 for x in rows if x[1] >= 0.8 and x[2] <= 0.1 and x[3] == 0)
    whole = sum(1 for x in rows if x[5])
    print(f"{rule:8} {model}    {person:8} {len(rows):5}  {st.fmean(r):.3f}   {min(r):.3f}    "
          f"{sum(ho):3} ({sum(1 for h in ho if h):d})            "
          f"{st.fmean(x[2] for x in rows):.3f}            {bar}/{len(rows)}       "
          f"{whole}/{len(rows)}")
