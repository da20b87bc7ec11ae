#!/usr/bin/env python3
"""Adversarial sweep of the `kinergy` CLI (Python 3 standard library only).

Generates many bad or tricky cases (fixed seed: a re-run tries the same cases) against the
CLI's surfaces, runs each with a timeout in a scratch folder under /tmp, and classifies each
outcome:

  panic        exit 101, "panicked" in stderr, or death by a signal we did not send
  hang         timeout; an interrupted run that did not stop within 5 s; reading > 5 s (fam. 6)
  data_loss    an input file changed or removed (bytes snapshotted before and after), or a
               result silently overwritten by another one
  wrong_exit0  exit 0 where the family expects a refusal; "inf"/"NaN"/a number of > 30 digits
               in stdout/stderr/output files (user input echoed in `backticks` excepted); or
               exit 0 with an output that is malformed or ambiguous (broken CSV/Markdown,
               rows of distinct reaches that cannot be told apart)
  debris       a `.*.tmp` file left after a run that ended by itself; an output written on a
               non-zero exit where the command must write nothing; an empty output folder
               created by a failed run
  bad_message  stderr over 2,000 bytes; an exit-2 message that does not name the offending
               file/flag; exit 1 where a refusal (exit 2) is expected; no message at all; a
               message quoting a 100+-digit number of the input in full
  unexpected_fail  a non-zero exit where the family expects a normal run (reported
               separately so that over-strict refusals are visible, not hidden in "ok")
  ok           expected behaviour

Families (see `FAMILIES`): 1 outdir_inputs, 2 arm_pairs, 3 scene_mesh, 4 fit_o_clip,
5 sigint, 6 dof_names, 7 targets, 8 mutations, 9 sigkill, 10 weird_paths, 11 holdout_arms.

Usage:
  python3 tools/adversarial-sweep.py [--kinergy PATH] [--quick] [--only FAMILY,...]
                                      [--scratch DIR] [--keep] [--seed N]
Writes /tmp/sweep-summary.txt (the table), /tmp/sweep-report.txt (every non-ok case: command,
exit, first 300 bytes of stderr) and /tmp/sweep-cases.jsonl (every case). Exit status 0 when
every case is ok, 1 otherwise.
"""

import argparse
import csv
import hashlib
import io
import json
import math
import os
import random
import re
import shlex
import shutil
import signal
import stat
import subprocess
import sys
import time

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_KINERGY = os.path.join(REPO, "target", "release", "kinergy")
DATA = os.path.join(REPO, "data-synthetic")
BOOKSHELF = os.path.join(REPO, "examples", "bookshelf")
TESTDATA = os.path.join(REPO, "tests", "data")

CLASSES = ["panic", "hang", "data_loss", "wrong_exit0", "debris", "unexpected_fail",
           "bad_message", "ok"]
MIB = 1024 * 1024
LIMIT_16 = 16 * MIB
STOP_WITHIN = 5.0  # seconds an interrupted run may take to stop
SLOW = 5.0  # seconds a params file may take to read (family 6)

K = None  # path of the kinergy binary
SCR = None  # scratch root
FIX = None  # fixtures folder
RNG = None

# ----------------------------------------------------------------------------- utilities


def w(path, data):
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    mode = "wb" if isinstance(data, (bytes, bytearray)) else "w"
    with open(path, mode, **({} if mode == "wb" else {"newline": ""})) as f:
        f.write(data)


def rb(path):
    with open(path, "rb") as f:
        return f.read()


def kin(args, cwd=None, check=True, timeout=300):
    r = subprocess.run([K] + args, cwd=cwd, stdin=subprocess.DEVNULL,
                       capture_output=True, timeout=timeout)
    if check and r.returncode != 0:
        raise SystemExit("fixture command failed: kinergy %s\n%s" % (
            " ".join(args), r.stderr.decode(errors="replace")))
    return r


def sha(data):
    return hashlib.sha256(data).hexdigest()[:16]


def snap(path, follow=True, depth=0):
    """A hashable description of a path: file bytes, symlink target, folder tree."""
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return ("missing",)
    except OSError as e:
        return ("error", e.errno)
    if stat.S_ISLNK(st.st_mode):
        target = os.readlink(path)
        inner = None
        if follow and depth == 0:
            try:
                os.stat(path)
                inner = snap(os.path.realpath(path), follow=False, depth=1)
            except OSError as e:
                inner = ("unresolvable", e.errno)
        return ("link", target, inner)
    if stat.S_ISDIR(st.st_mode):
        try:
            names = sorted(os.listdir(path))
        except OSError as e:
            return ("dir-error", e.errno)
        return ("dir", tuple((n, snap(os.path.join(path, n), follow=False, depth=depth + 1))
                             for n in names))
    if stat.S_ISREG(st.st_mode):
        try:
            return ("file", sha(rb(path)))
        except OSError as e:
            return ("file-error", e.errno)
    return ("other", stat.S_IFMT(st.st_mode))


def walk_nofollow(root):
    """(dirs, files) under root, not following symlinks; paths relative to root."""
    dirs, files = set(), {}
    if not os.path.isdir(root) or os.path.islink(root):
        return dirs, files
    for base, dnames, fnames in os.walk(root, followlinks=False):
        rel = os.path.relpath(base, root)
        for d in dnames:
            p = os.path.join(base, d)
            if os.path.islink(p):
                files[os.path.normpath(os.path.join(rel, d))] = ("link", os.readlink(p))
            else:
                dirs.add(os.path.normpath(os.path.join(rel, d)))
        for f in fnames:
            p = os.path.join(base, f)
            try:
                st = os.lstat(p)
                if stat.S_ISREG(st.st_mode):
                    files[os.path.normpath(os.path.join(rel, f))] = (st.st_size, st.st_mtime_ns,
                                                                    st.st_ino)
                else:
                    files[os.path.normpath(os.path.join(rel, f))] = ("special", st.st_mode)
            except OSError:
                pass
    return dirs, files


def tmp_debris(root):
    out = []
    if not os.path.isdir(root):
        return out
    for base, dnames, fnames in os.walk(root, followlinks=False):
        for f in fnames:
            if f.startswith(".") and f.endswith(".tmp"):
                out.append(os.path.join(base, f))
    return out


def dir_is_empty_tree(path):
    for _base, _d, fnames in os.walk(path, followlinks=False):
        if fnames:
            return False
    return True


BAD_TOKEN = re.compile(r"(?<![A-Za-z0-9_])[-+]?(?:inf(?:inity)?|nan)(?![A-Za-z0-9_])", re.I)
LONG_NUM = re.compile(r"\d{31,}")
BACKTICK = re.compile(r"`[^`\n]*`")


def bad_numbers(text, echo=()):
    """'inf'/'NaN'/a number with more than 30 digits in text (echoed input stripped)."""
    text = BACKTICK.sub("``", text)
    for e in echo:
        if e:
            text = re.sub(re.escape(e), " ", text, flags=re.I)
    m = BAD_TOKEN.search(text)
    if m:
        s = max(0, m.start() - 40)
        return "%r in %r" % (m.group(0), text[s:m.end() + 40])
    m = LONG_NUM.search(text)
    if m:
        s = max(0, m.start() - 20)
        return "a %d-digit number in %r" % (len(m.group(0)), text[s:m.start() + 60])
    return None


def scan_paths(paths):
    """Text files under paths (files or folders), as (path, text)."""
    out = []
    for p in paths:
        cands = []
        if os.path.isdir(p) and not os.path.islink(p):
            for base, _d, fn in os.walk(p):
                cands += [os.path.join(base, f) for f in fn]
        elif os.path.isfile(p):
            cands.append(p)
        for c in cands:
            if c.endswith((".png", ".gif")) or os.path.basename(c).startswith("."):
                continue
            try:
                if os.path.getsize(c) > 40 * MIB:
                    continue
                data = rb(c)
            except OSError:
                continue
            if b"\0" in data[:8192]:
                continue
            text = data.decode("utf-8", errors="replace")
            if c.endswith(".html"):
                # A page's own numbers are its data block; the inlined three.js spells NaN
                # in its code.
                m = re.search(r'<script id="kinergy-data"[^>]*>(.*?)</script>', text, re.S)
                text = m.group(1) if m else text
            out.append((c, text))
    return out


def csv_rows(path):
    with open(path, newline="", encoding="utf-8", errors="replace") as f:
        return [r for r in csv.reader(f)]


def md_table_problems(text):
    """Rows of a Markdown table whose cell count differs from its header's."""
    probs = []
    lines = text.split("\n")
    i = 0
    while i < len(lines):
        if lines[i].startswith("|") and i + 1 < len(lines) and re.match(r"^\|(\s*:?-+:?\s*\|)+\s*$", lines[i + 1]):
            ncols = count_cells(lines[i])
            j = i + 2
            while j < len(lines) and lines[j].startswith("|"):
                if count_cells(lines[j]) != ncols:
                    probs.append("table row %r has %d cells, header %d" % (lines[j][:80], count_cells(lines[j]), ncols))
                j += 1
            # a table row that ends without its closing pipe: the cell had a raw newline
            if j < len(lines) and lines[j - 1].startswith("|") and not lines[j - 1].rstrip().endswith("|"):
                probs.append("table row %r is cut (raw newline in a cell)" % lines[j - 1][:80])
            i = j
        else:
            i += 1
    return probs


def count_cells(line):
    # unescaped pipes outside code spans
    s = re.sub(r"\\\|", "", line)
    s = re.sub(r"(`+)(.*?)\1", lambda m: "x" * 1, s)
    return s.count("|") - 1


def q(args):
    return " ".join(shlex.quote(a) for a in args)


# ----------------------------------------------------------------------------- cases


class Case:
    def __init__(self, family, label, argv, cwd, **kw):
        self.family = family
        self.label = label
        self.argv = argv
        self.cwd = cwd
        self.setup = kw.get("setup")  # () -> None, creates files
        self.inputs = kw.get("inputs", [])  # paths that must not change
        self.expect = kw.get("expect", "refuse")  # refuse | fail | run | success | any
        self.hints = kw.get("hints", [])  # an exit-2 message names one of these
        self.nowrite = kw.get("nowrite", [])  # paths that must stay as they were on failure
        self.nowrite_dirs = kw.get("nowrite_dirs", [])  # no new/changed file on failure
        self.scan = kw.get("scan", [])  # outputs to scan for inf/NaN/long numbers
        self.echo = kw.get("echo", [])
        self.post = kw.get("post")  # (case, res) -> [(class, detail)]
        self.timeout = kw.get("timeout", 60)
        self.runner = kw.get("runner")  # custom runner (signals)
        self.slow = kw.get("slow")  # wall time above which the case is a hang
        self.case_dir = kw.get("case_dir")
        self.repro = kw.get("repro")  # extra reproduction text


class Res:
    def __init__(self):
        self.rc = None
        self.wall = 0.0
        self.out = b""
        self.err = b""
        self.timed_out = False
        self.we_signalled = False  # a signal we sent ended the process
        self.ended_by_itself = True
        self.notes = []
        self.extra = {}


def spawn(argv, cwd):
    return subprocess.Popen([K] + argv, cwd=cwd, stdin=subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True)


def run_plain(case):
    res = Res()
    t0 = time.monotonic()
    p = spawn(case.argv, case.cwd)
    try:
        res.out, res.err = p.communicate(timeout=case.timeout)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        res.out, res.err = p.communicate()
        res.timed_out = True
        res.ended_by_itself = False
    res.wall = time.monotonic() - t0
    res.rc = p.returncode
    return res


def classify(case, res, pre_inputs, pre_tree, pre_nowrite):
    f = []
    err = res.err.decode("utf-8", errors="replace")
    out = res.out.decode("utf-8", errors="replace")
    rc = res.rc
    if res.timed_out:
        f.append(("hang", "no exit within %gs" % case.timeout))
    if case.slow and res.wall > case.slow and not res.timed_out:
        f.append(("hang", "took %.1fs (limit %gs)" % (res.wall, case.slow)))
    if rc == 101 or "panicked" in err:
        f.append(("panic", "exit %s, panic message" % rc))
    elif rc is not None and rc < 0 and not res.we_signalled:
        f.append(("panic", "killed by signal %d (crash)" % -rc))
    # inputs
    for p, before in pre_inputs.items():
        after = snap(p)
        if after != before:
            f.append(("data_loss", "input %s changed (%s -> %s)" % (p, str(before)[:60], str(after)[:60])))
    # expectations on the exit
    finished = not res.timed_out and not res.we_signalled
    if finished:
        if case.expect in ("refuse", "fail") and rc == 0:
            f.append(("wrong_exit0", "exit 0 where a refusal was expected"))
        if case.expect == "refuse" and rc == 1:
            f.append(("bad_message", "exit 1 where a refusal (exit 2) was expected"))
        if case.expect == "success" and rc not in (0,) and rc is not None and rc >= 0 and rc != 101:
            f.append(("unexpected_fail", "exit %d where a normal run was expected" % rc))
        if case.expect == "run" and rc == 2:
            f.append(("unexpected_fail", "exit 2 for a reachable/valid input"))
        if rc not in (0, 1, 2, 101) and rc is not None and rc >= 0:
            f.append(("bad_message", "unexpected exit status %d" % rc))
    # output content
    texts = [("stdout", out), ("stderr", err)] + scan_paths(case.scan)
    for where, text in texts:
        b = bad_numbers(text, case.echo)
        if b:
            f.append(("wrong_exit0", "%s: %s" % (where if where in ("stdout", "stderr") else os.path.relpath(where, case.case_dir or "/"), b)))
            break
    # a message that quotes a huge number of the user's in full (inf/nan quoted are fine; an
    # echo cut to ~60 characters with "… (N more characters)", as most messages do, is fine)
    for where, text in texts[:2]:
        quoted = " ".join(BACKTICK.findall(text))
        m = re.search(r"\d{100,}", quoted)
        if m:
            f.append(("bad_message", "%s quotes a %d-digit number of the input verbatim (%d bytes)"
                      % (where, len(m.group(0)), len(text.encode()))))
            break
    # debris
    if res.ended_by_itself:
        roots = [case.case_dir] if case.case_dir else []
        for r in roots:
            for t in tmp_debris(r):
                f.append(("debris", "temporary file left: %s" % os.path.relpath(t, r)))
    if finished and rc not in (0, None):
        for p, before in pre_nowrite.items():
            if p in pre_inputs:
                continue
            if snap(p) != before:
                if rc == 1 and os.path.basename(p) in err:
                    continue  # a task failure that writes its best motion and says so
                f.append(("debris", "%s written/changed by a failed run (exit %s)" % (p, rc)))
        for d, before_files in pre_tree.get("nowrite_dirs", {}).items():
            _dirs, files = walk_nofollow(d)
            for rel, meta in files.items():
                if rel not in before_files or before_files[rel] != meta:
                    full = os.path.join(d, rel)
                    if full in pre_inputs:
                        continue
                    f.append(("debris", "%s written by a failed run" % full))
        if case.case_dir:
            dirs_before = pre_tree.get("dirs", set())
            dirs_after, _ = walk_nofollow(case.case_dir)
            for d in sorted(dirs_after - dirs_before):
                full = os.path.join(case.case_dir, d)
                parent_new = os.path.dirname(d) in (dirs_after - dirs_before)
                if not parent_new and dir_is_empty_tree(full):
                    f.append(("debris", "empty folder %s created by a failed run" % d))
    # messages
    if len(res.err) > 2000:
        f.append(("bad_message", "stderr is %d bytes" % len(res.err)))
    if finished and rc in (1, 2) and not err.strip():
        f.append(("bad_message", "exit %d with nothing on stderr" % rc))
    if finished and rc == 2 and case.hints and err.strip():
        if not any(h and h in err for h in case.hints):
            f.append(("bad_message", "exit-2 message names none of %r" % (case.hints[:4],)))
    if case.post:
        try:
            f += case.post(case, res) or []
        except Exception as e:  # a checker bug must not end the sweep
            f.append(("bad_message", "post-check error: %r" % e))
    return f


def primary(findings):
    for c in CLASSES:
        if any(x[0] == c for x in findings):
            return c
    return "ok"


# ----------------------------------------------------------------------------- fixtures

SEG_MAIN = {}  # "pNN/rMM.bvh" -> (onset, end)
MANIFEST = {}  # "pNN/rMM.bvh" -> row
CLIPS = []  # "pNN/rMM.bvh"
DEAD_PID = None


def prepare_fixtures():
    global DEAD_PID
    os.makedirs(FIX)
    shutil.copytree(DATA, os.path.join(FIX, "ds"))
    shutil.copytree(BOOKSHELF, os.path.join(FIX, "bookshelf"))
    shutil.copy(os.path.join(TESTDATA, "006_14.bvh"), os.path.join(FIX, "006_14.bvh"))
    ds = os.path.join(FIX, "ds")
    for r in csv.DictReader(open(os.path.join(ds, "manifest.csv"), newline="")):
        MANIFEST[r["clip"]] = r
        CLIPS.append(r["clip"])
    kin(["fit", os.path.join(ds, "p01/r01.bvh"), "--model", "sa", "--budget", "50", "-q",
         "-o", os.path.join(FIX, "p_sa.json")])
    kin(["fit", os.path.join(ds, "p01/r09.bvh"), "--model", "sc", "--budget", "50", "-q",
         "-o", os.path.join(FIX, "p_sc.json")])
    kin(["fit", os.path.join(ds, "p01"), "--model", "sa", "--budget", "20", "--field", "-q",
         "-o", os.path.join(FIX, "field.json")])
    kin(["segment", ds, "--select", "main", "-q", "--manifest", os.path.join(FIX, "seg_main.csv")])
    for row in read_segments(os.path.join(FIX, "seg_main.csv")):
        clip = row["clip"][3:] if row["clip"].startswith("ds/") else row["clip"]
        SEG_MAIN[clip] = (int(row["onset"]), int(row["end"]))
    # segments with targets (world meters, from the manifest), 3 and 14 rows of p01
    for n, name in ((3, "seg_tgt3.csv"), (14, "seg_tgt14.csv")):
        rows = []
        for c in CLIPS:
            if c.startswith("p01/") and len(rows) < n:
                m = MANIFEST[c]
                o, e = SEG_MAIN[c]
                rows.append([os.path.join(ds, c), o, e, "right", "reach", "p01",
                             m["target_x"], m["target_y"], m["target_z"]])
        w(os.path.join(FIX, name), seg_text(rows, targets=True))
    r = kin(["plan", "--scene", os.path.join(FIX, "bookshelf", "scene.json"), "--target",
             "-0.25,1.1,0.3", "--budget-ms", "300", "-o", os.path.join(FIX, "plan.bvh"), "--json"])
    w(os.path.join(FIX, "plan_report.json"), r.stdout)
    # weird paths (family 10)
    wd = os.path.join(FIX, "weird")
    os.makedirs(wd)
    os.mkfifo(os.path.join(wd, "fifo"))
    os.symlink("loop2", os.path.join(wd, "loop1"))
    os.symlink("loop1", os.path.join(wd, "loop2"))
    os.symlink("nowhere.bvh", os.path.join(wd, "dangling.bvh"))
    os.makedirs(os.path.join(wd, "emptydir"))
    os.makedirs(os.path.join(wd, "txtdir"))
    w(os.path.join(wd, "txtdir", "notes.txt"), "not a capture\n")
    os.makedirs(os.path.join(wd, "bvhdir", "a.bvh"))
    os.makedirs(os.path.join(wd, "fifodir"))
    os.mkfifo(os.path.join(wd, "fifodir", "a.bvh"))
    os.makedirs(os.path.join(wd, "loopdir"))
    os.symlink("b.bvh", os.path.join(wd, "loopdir", "a.bvh"))
    os.symlink("a.bvh", os.path.join(wd, "loopdir", "b.bvh"))
    os.makedirs(os.path.join(wd, "dangdir"))
    os.symlink("gone.bvh", os.path.join(wd, "dangdir", "a.bvh"))
    os.makedirs(os.path.join(wd, "selfloopdir"))
    os.symlink(".", os.path.join(wd, "selfloopdir", "again"))
    p = subprocess.Popen(["true"])
    p.wait()
    DEAD_PID = p.pid


def read_segments(path):
    lines = [l for l in open(path, newline="").read().split("\n") if not l.startswith("#")]
    return list(csv.DictReader(io.StringIO("\n".join(lines))))


def seg_text(rows, targets=False, header=None, comment=True, newline="\n"):
    buf = io.StringIO()
    wr = csv.writer(buf, lineterminator=newline)
    if comment:
        buf.write("# kinergy segments (adversarial sweep)" + newline)
    wr.writerow(header or (["clip", "onset", "end", "arm", "label", "person"] +
                           (["target_x", "target_y", "target_z"] if targets else [])))
    for r in rows:
        wr.writerow(r)
    return buf.getvalue()


def ds(c):
    return os.path.join(FIX, "ds", c)


class CaseDirs:
    def __init__(self):
        self.n = {}

    def new(self, fam):
        self.n[fam] = self.n.get(fam, 0) + 1
        return os.path.join(SCR, "cases", fam, "%04d" % self.n[fam])


DIRS = CaseDirs()


def copy_clip(src_rel, dst):
    os.makedirs(os.path.dirname(dst), exist_ok=True)
    shutil.copy(ds(src_rel), dst)


def sample(rng, items, n):
    items = list(items)
    if n >= len(items):
        return items
    return rng.sample(items, n)


# ----------------------------------------------------------------------------- family 1


def fam_outdir_inputs(rng, n):
    fam = "1_outdir_inputs"
    cases = []
    dspell = ["out", "out/", "./out", "out/.", "out//", "ABS", "clips/../out", "lnk"]
    ispell = ["out/N", "./out/N", "ABS/out/N", "lnk/N", "out//N", "out/./N", "inlink", "hard"]

    def D(c, s):
        return os.path.join(c, "out") if s == "ABS" else s

    def I(c, s, name):
        if s == "ABS/out/N":
            return os.path.join(c, "out", name)
        if s == "inlink":
            return "inlink" + os.path.splitext(name)[1]
        if s == "hard":
            return "hard" + os.path.splitext(name)[1]
        return s.replace("N", name)

    def base_setup(c, name, content_path, spell):
        def setup():
            os.makedirs(os.path.join(c, "out"), exist_ok=True)
            os.makedirs(os.path.join(c, "clips"), exist_ok=True)
            os.symlink("out", os.path.join(c, "lnk"))
            target = os.path.join(c, "out", name)
            os.makedirs(os.path.dirname(target), exist_ok=True)
            shutil.copy(content_path, target)
            if spell == "inlink":
                os.symlink(os.path.join("out", name), os.path.join(c, I(c, spell, name)))
            if spell == "hard":
                os.link(target, os.path.join(c, I(c, spell, name)))
            for cl in ("p01/r01.bvh", "p01/r02.bvh", "p01/r03.bvh"):
                copy_clip(cl, os.path.join(c, "clips", cl))
            shutil.copy(os.path.join(FIX, "p_sa.json"), os.path.join(c, "P.json"))
        return setup

    def seg_for(clips):
        return seg_text([[cl, *SEG_MAIN[cl.split("clips/")[-1]], "right", "reach", "p01"] for cl in clips])

    combos = []
    # compare per clip
    for name in ["results.csv", "summary.md", "fig3.svg", "fig3.png", "fig4.svg", "fig4.png"]:
        for kind in ["segments", "clip", "segclip"]:
            for d in dspell:
                for s in ispell:
                    combos.append(("compare", name, kind, d, s))
    for name in ["holdout.csv", "summary.md"]:
        for kind in ["segments", "segclip"]:
            for d in dspell:
                for s in ispell:
                    combos.append(("compare_holdout", name, kind, d, s))
    for name in ["style.csv", "summary.md", "speed.svg", "speed.png", "strip.svg", "strip.png",
                 "r01.params.bvh", "r01.profile.bvh"]:
        for kind in ["params", "clip"]:
            for d in dspell:
                for s in ispell:
                    combos.append(("style", name, kind, d, s))
    for name in ["manifest.csv", "segments.csv", "p01/r01.bvh", "p01/r02.bvh"]:
        for d in dspell:
            for s in ispell:
                combos.append(("synth", name, "params", d, s))
    # a library's result names: the take's whole file name + `.json`, `@START-END` for a take of
    # several reaches, and `@ARM` after it where two reaches share their frames
    fit_names = ["r01.bvh.json", "r02.bvh.json", "r01.bvh@7-71.json", "r01.bvh@7-71@left.json"]
    # newer binaries also write tables into the folder (`fit --help` names them)
    fit_help = kin(["fit", "--help"], check=False).stdout.decode(errors="replace")
    fit_names += [t for t in ("library.csv", "skipped.csv") if t in fit_help]
    for name in fit_names:
        for kind in ["segments", "clip_self"]:
            for d in dspell:
                for s in ispell:
                    if kind == "clip_self" and s in ("inlink", "hard"):
                        continue
                    if kind == "clip_self" and "@" in name:
                        continue  # a take of one reach is never named with `@`
                    combos.append(("fit", name, kind, d, s))
    weights = {"compare": 0.30, "compare_holdout": 0.10, "style": 0.30, "synth": 0.12, "fit": 0.18}
    chosen = []
    for cmd, wgt in weights.items():
        chosen += sample(rng, [x for x in combos if x[0] == cmd], max(2, int(n * wgt)))
    for cmd, name, kind, d, s in chosen:
        c = DIRS.new(fam)
        dd = D(c, d)
        ip = I(c, s, name)
        argv = []
        content = None
        extra_setup = None
        if cmd in ("compare", "compare_holdout"):
            argv = ["compare", "--models", "sa", "--optimizers", "svd", "--no-baselines",
                    "--budget", "20", "-q", "-o", dd]
            if cmd == "compare_holdout":
                argv += ["--per", "person", "--holdout", "1"]
            if kind == "segments":
                content = os.path.join(FIX, "seg_main.csv")
                segrows = ["clips/p01/r01.bvh", "clips/p01/r02.bvh", "clips/p01/r03.bvh"]
                # the segments file sits in out/: clips relative to it
                def extra_setup(c=c, segrows=segrows, name=name):
                    w(os.path.join(c, "out", name), seg_for([os.path.join(c, x) for x in segrows]))
                argv += ["--segments", ip]
            elif kind == "clip":
                content = ds("p01/r01.bvh")
                argv += [ip]
            else:  # the segments file names a clip stored at out/NAME
                content = ds("p01/r04.bvh")
                cl = ip if s not in ("inlink", "hard") else ip
                def extra_setup(c=c, cl=cl):
                    rows = [[cl, 1, 112, "right", "reach", "p01"]]
                    for x in ("clips/p01/r01.bvh", "clips/p01/r02.bvh"):
                        rows.append([os.path.join(c, x), *SEG_MAIN[x.split("clips/")[-1]], "right", "reach", "p01"])
                    w(os.path.join(c, "seg.csv"), seg_text(rows))
                argv += ["--segments", "seg.csv"]
        elif cmd == "style":
            argv = ["style", "clips/p01/r01.bvh", "-q", "-o", dd]
            if kind == "params":
                content = os.path.join(FIX, "p_sa.json")
                argv += ["--params", ip]
            else:
                content = ds("p01/r02.bvh")
                argv += [ip, "--params", "P.json"]
        elif cmd == "synth":
            content = os.path.join(FIX, "p_sa.json")
            argv = ["synth", "--params", ip, "-o", dd, "--persons", "1", "--reaches", "2", "-q"]
        elif cmd == "fit":
            outflag = ["--out-dir", dd] if rng.random() < 0.6 else ["-o", dd.rstrip("/") + "/"]
            argv = ["fit", "--model", "sa", "--budget", "20", "--per", "clip", "-q"] + outflag
            if kind == "segments":
                content = os.path.join(FIX, "seg_main.csv")
                def extra_setup(c=c, name=name):
                    cl = lambda x: os.path.join(c, "clips", "p01", x)
                    rows = [[cl("r01.bvh"), 7, 71, "right", "reach", "p01"],
                            [cl("r02.bvh"), 9, 101, "right", "reach", "p01"]]
                    if "@left" in name:
                        rows.append([cl("r01.bvh"), 7, 71, "left", "reach", "p01"])
                    elif "@" in name:
                        rows.append([cl("r01.bvh"), 10, 60, "right", "reach", "p01"])
                    w(os.path.join(c, "out", name), seg_text(rows))
                    # clips are in clips/p01: outputs are named from their common folder
                argv += ["--segments", ip]
            else:  # a capture stored at out/NAME: its own result is out/NAME.json
                content = ds("p01/r01.bvh")
                argv += [ip]
        setup0 = base_setup(c, name, content, s)

        def setup(setup0=setup0, extra_setup=extra_setup):
            setup0()
            if extra_setup:
                extra_setup()
        expect = "any" if s == "hard" else "refuse"
        if cmd == "fit" and kind == "clip_self" and name.endswith(".json"):
            # a take is never its own result (`r01.bvh.json` fits into `r01.bvh.json.json`):
            # nothing to refuse, but the take must stay as it was
            expect = "success"
        hints = [os.path.basename(name), name, ip, os.path.basename(ip)]
        inputs = [os.path.join(c, "out", name), os.path.join(c, "clips"), os.path.join(c, "P.json")]
        if s in ("inlink", "hard"):
            inputs.append(os.path.join(c, ip))
        if os.path.exists(os.path.join(c, "seg.csv")) or kind == "segclip":
            inputs.append(os.path.join(c, "seg.csv"))
        cases.append(Case(fam, "%s %s at %s, -o %s, input spelled %s" % (cmd, kind, name, d, s),
                          argv, c, setup=setup, inputs=inputs, expect=expect, hints=hints,
                          nowrite_dirs=[os.path.join(c, "out")] if expect == "refuse" else [],
                          case_dir=c, scan=[os.path.join(c, "out")]))
    return cases


# ----------------------------------------------------------------------------- family 2


def fam_arm_pairs(rng, n):
    fam = "2_arm_pairs"
    cases = []
    spells = ["clips/{c}", "./clips/{c}", "ABS", "clips//{c}", "clips/{p}/../{c}"]
    for i in range(n):
        c = DIRS.new(fam)
        npairs = rng.choice([1, 1, 1, 2, 3])
        same_base = rng.random() < 0.3
        chosen = []
        take = rng.choice(["r%02d" % k for k in range(1, 15)])
        persons = rng.sample(["p01", "p02", "p03", "p04"], 3)
        for k in range(npairs):
            if same_base:
                chosen.append("%s/%s.bvh" % (persons[k], take))
            else:
                chosen.append(rng.choice(CLIPS))
        chosen = list(dict.fromkeys(chosen))
        rows = []
        spelling = rng.choice(["same", "same", "mixed"])
        for cl in chosen:
            frames = int(MANIFEST[cl]["frames"])
            if rng.random() < 0.6:
                o, e = SEG_MAIN[cl]
            else:
                o = rng.randint(0, 15)
                e = rng.randint(min(frames, o + 25), frames)
            arms = ["right", "left"] if rng.random() < 0.5 else ["left", "right"]
            pair = rng.sample(spells, 2) if spelling == "mixed" else [rng.choice(spells)] * 2
            for a, sp in zip(arms, pair):
                p = os.path.dirname(cl)
                path = os.path.join(c, "clips", cl) if sp == "ABS" else sp.format(c=cl, p=p)
                rows.append([path, o, e, a, "reach", p])
        if rng.random() < 0.3:
            rng.shuffle(rows)
        mode = rng.choice(["out-dir", "out-dir", "o-slash", "compare"]) if i % 6 else "compare"
        text = seg_text(rows, comment=rng.random() < 0.5)

        def setup(c=c, chosen=chosen, text=text):
            for cl in chosen:
                copy_clip(cl, os.path.join(c, "clips", cl))
            w(os.path.join(c, "seg.csv"), text)
        nrows = len(rows)
        if mode == "compare":
            argv = ["compare", "--segments", "seg.csv", "--models", "sa", "--optimizers", "svd",
                    "--no-baselines", "--budget", "20", "-q", "-o", "cmp"]
        else:
            argv = ["fit", "--segments", "seg.csv", "--model", "sa", "--budget", "20", "--per",
                    "clip", "-q"] + (["--out-dir", "out"] if mode == "out-dir" else ["-o", "out/"])

        def post(case, res, nrows=nrows, mode=mode, rows=rows):
            f = []
            if res.rc != 0:
                return f
            if mode == "compare":
                path = os.path.join(case.cwd, "cmp", "results.csv")
                if not os.path.exists(path):
                    return [("wrong_exit0", "exit 0 but no results.csv")]
                hdr = csv_rows(path)[0]
                if not any(h in hdr for h in ("arm", "onset", "end", "reach")):
                    f.append(("wrong_exit0", "results.csv has %d reaches of one clip differing by arm "
                              "but no column (arm/onset/end) to tell their rows apart: header %s"
                              % (2, ",".join(hdr))))
                return f
            outd = os.path.join(case.cwd, "out")
            files = []
            for base, dnames, fn in os.walk(outd):
                if base == outd and "shards" in dnames:
                    dnames.remove("shards")  # the library's shard records, not results
                files += [os.path.join(base, x) for x in fn if x.endswith(".json") and not x.startswith(".")]
            if len(files) != nrows:
                f.append(("data_loss", "%d reaches but %d result files (%s): a result was overwritten"
                          % (nrows, len(files), ", ".join(sorted(os.path.relpath(x, outd) for x in files)))))
            seen = []
            for x in files:
                try:
                    doc = json.load(open(x))
                    r0 = doc["fit"]["reaches"][0]
                    seen.append((os.path.basename(r0["clip"]), r0["arm"]["side"], tuple(r0["frames"])))
                except Exception as e:
                    f.append(("wrong_exit0", "%s does not parse as a result: %r" % (x, e)))
            if len(set(seen)) != len(seen):
                f.append(("data_loss", "two result files hold the same reach: %r" % seen))
            return f
        cases.append(Case(fam, "%s, %s spelling of each clip, %d rows (%s)" % (
            mode, spelling, nrows, ", ".join("%s:%s" % (r[0].replace(c + "/", "$PWD/"), r[3]) for r in rows)),
                          argv, c, setup=setup, inputs=[os.path.join(c, "clips"), os.path.join(c, "seg.csv")],
                          expect="success", hints=["seg.csv", "out", "cmp"], post=post, case_dir=c,
                          scan=[os.path.join(c, "out"), os.path.join(c, "cmp")]))
    return cases


# ----------------------------------------------------------------------------- family 3


def fam_scene_mesh(rng, n):
    fam = "3_scene_mesh"
    cases = []
    mesh_kinds = ["obj", "sub", "abs", "outside", "dotslash", "bvhname", "gifname", "pngname", "svgname"]
    spells = ["rel", "dot", "abs", "dslash", "dotdir", "updown", "dirlink", "filelink"]
    scene_text = open(os.path.join(FIX, "bookshelf", "scene.json")).read()
    for i in range(n):
        c = DIRS.new(fam)
        mk = rng.choice(mesh_kinds)
        mesh_rel = {"obj": "scene/shelf.obj", "sub": "scene/meshes/shelf.obj", "abs": "scene/shelf.obj",
                    "outside": "mesh/shelf.obj", "dotslash": "scene/shelf.obj", "bvhname": "scene/shelf.bvh",
                    "gifname": "scene/shelf.gif", "pngname": "scene/shelf.png", "svgname": "scene/shelf.svg"}[mk]
        ref = {"obj": "shelf.obj", "sub": "meshes/shelf.obj", "abs": os.path.join(c, "scene/shelf.obj"),
               "outside": "../mesh/shelf.obj", "dotslash": "./shelf.obj", "bvhname": "shelf.bvh",
               "gifname": "shelf.gif", "pngname": "shelf.png", "svgname": "shelf.svg"}[mk]
        sp = rng.choice(spells)
        mesh_abs = os.path.join(c, mesh_rel)
        d, b = os.path.split(mesh_rel)
        spelled = {"rel": mesh_rel, "dot": "./" + mesh_rel, "abs": mesh_abs,
                   "dslash": d + "//" + b, "dotdir": d + "/./" + b,
                   "updown": d + "/../" + d + "/" + b if "/" not in d else d + "/../" + os.path.basename(d) + "/" + b,
                   "dirlink": "dlink/" + b, "filelink": "flink" + os.path.splitext(b)[1]}[sp]
        control = rng.random() < 0.15
        tool = rng.choice(["plan", "plan", "animate"])

        def setup(c=c, ref=ref, mesh_abs=mesh_abs, sp=sp):
            os.makedirs(os.path.join(c, "scene"))
            w(os.path.join(c, "scene", "scene.json"), scene_text.replace('"shelf.obj"', json.dumps(ref)))
            os.makedirs(os.path.dirname(mesh_abs), exist_ok=True)
            shutil.copy(os.path.join(FIX, "bookshelf", "shelf.obj"), mesh_abs)
            os.symlink(os.path.dirname(mesh_abs), os.path.join(c, "dlink"))
            os.symlink(mesh_abs, os.path.join(c, "flink" + os.path.splitext(mesh_abs)[1]))
            shutil.copy(os.path.join(FIX, "plan.bvh"), os.path.join(c, "clip.bvh"))
            shutil.copy(os.path.join(FIX, "plan_report.json"), os.path.join(c, "report.json"))
            shutil.copy(os.path.join(FIX, "p_sa.json"), os.path.join(c, "P.json"))
        inputs = [os.path.join(c, "scene"), os.path.join(c, "mesh"), mesh_abs,
                  os.path.join(c, "clip.bvh"), os.path.join(c, "report.json"), os.path.join(c, "P.json")]
        what = ""
        if tool == "plan":
            mode = rng.choice(["target", "relocate", "grasp", "target-params"])
            argv = ["plan", "--scene", "scene/scene.json", "--seed", str(rng.randint(0, 9)),
                    "--budget-ms", "200", "-q"]
            if mode.startswith("target"):
                argv += ["--target", rng.choice(["-0.25,1.1,0.3", "-0.2,1.0,0.25", "0.1,1.2,0.3"])]
            elif mode == "relocate":
                argv += ["--task", "relocate", "--object", "blue_book", "--to", "-0.22,1.49,0.50"]
            else:
                argv += ["--task", "grasp", "--object", rng.choice(["blue_book", "grey_book"])]
            if mode == "target-params":
                argv += ["--params", "P.json"]
            other = rng.choice(["mesh", "mesh", "mesh", "scene", "params"]) if mode == "target-params" else \
                rng.choice(["mesh", "mesh", "mesh", "scene"])
            if control:
                outp = "out.bvh"
            elif other == "scene":
                outp = "scene/scene.json"
            elif other == "params":
                outp = "P.json"
            else:
                outp = spelled
            argv += ["-o", outp]
            what = "plan %s -o %s" % (mode, outp)
            hints = [os.path.basename(outp), outp, "-o"]
        else:
            argv = ["animate", "clip.bvh", "--scene", "scene/scene.json", "--size", "64x64",
                    "--fps", "4", "--strip-frames", "1", "-q"]
            if rng.random() < 0.4:
                argv += ["--report", "report.json"]
            ext = os.path.splitext(mesh_abs)[1]
            if control:
                argv += ["-o", "a.gif", "--strip", "a.svg"]
                what = "animate control"
            elif ext == ".gif":
                argv += ["-o", spelled, "--strip", "a.svg"]
                what = "animate -o mesh(.gif)"
            elif ext == ".png":
                if rng.random() < 0.5:
                    gif = spelled[:-4] + ".gif"
                    argv += ["-o", gif]
                    what = "animate -o %s (default strip = the .png mesh)" % gif
                else:
                    argv += ["-o", "a.gif", "--strip", spelled]
                    what = "animate --strip mesh(.png)"
            elif ext == ".svg":
                argv += ["-o", "a.gif", "--strip", spelled]
                what = "animate --strip mesh(.svg)"
            else:
                argv += ["-o", spelled, "--strip", "a.png"]
                what = "animate -o mesh(%s)" % ext
            hints = [os.path.basename(mesh_abs), "-o", "--strip", ".gif"]
        cases.append(Case(fam, "%s; mesh %s (%s), output spelled %s%s" % (what, mk, ref if mk != "abs" else "ABS", sp,
                                                                          " [control]" if control else ""),
                          argv, c, setup=setup, inputs=inputs,
                          # a symlink to the mesh as the output: replacing the link keeps the mesh
                          expect="run" if control else ("any" if sp == "filelink" else "refuse"),
                          hints=hints, case_dir=c, nowrite_dirs=[] if control else [c],
                          scan=[os.path.join(c, "out.bvh")]))
    return cases


# ----------------------------------------------------------------------------- family 4


def fam_fit_o_clip(rng, n):
    fam = "4_fit_o_clip"
    cases = []
    clips = ["p01/r01.bvh", "p01/r02.bvh", "p01/r03.bvh", "p02/r01.bvh"]
    for i in range(n):
        c = DIRS.new(fam)
        seg_loc = rng.choice(["data", "segs", "root"])
        seg_paths = rng.choice(["rel", "abs", "dotrel"])
        cwd_kind = rng.choice(["c", "data"])
        cwd = c if cwd_kind == "c" else os.path.join(c, "data")
        seg_dir = {"data": os.path.join(c, "data"), "segs": os.path.join(c, "segs"), "root": c}[seg_loc]
        rows = []
        for cl in clips:
            absp = os.path.join(c, "data", cl)
            if seg_paths == "abs":
                p = absp
            else:
                p = os.path.relpath(absp, seg_dir)
                if seg_paths == "dotrel" and not p.startswith(".."):
                    p = "./" + p
            rows.append([p, *SEG_MAIN[cl], "right", "reach", cl.split("/")[0]])
        seg_abs = os.path.join(seg_dir, "seg.csv")
        first = rng.randrange(len(clips))
        other = rng.choice([k for k in range(len(clips)) if k != first])
        xkind = rng.choice(["rel", "dotrel", "abs", "dirlink", "filelink", "hardlink", "self", "segments",
                            "rel", "abs"])
        clip_abs = os.path.join(c, "data", clips[first])
        x_abs = os.path.join(c, "data", clips[other])

        def spell(path, how):
            rp = os.path.relpath(path, cwd)
            if how == "abs":
                return path
            if how == "dotrel":
                return rp if rp.startswith("..") else "./" + rp
            return rp
        if xkind == "self":
            x = spell(clip_abs, rng.choice(["rel", "dotrel", "abs"]))
            xtarget = clip_abs
        elif xkind == "segments":
            x = spell(seg_abs, rng.choice(["rel", "abs"]))
            xtarget = seg_abs
        elif xkind == "dirlink":
            x = spell(os.path.join(c, "dlink", clips[other]), "rel")
            xtarget = x_abs
        elif xkind == "filelink":
            x = spell(os.path.join(c, "xlink.bvh"), "rel")
            xtarget = x_abs
        elif xkind == "hardlink":
            x = spell(os.path.join(c, "xhard.bvh"), "rel")
            xtarget = x_abs
        else:
            x = spell(x_abs, xkind)
            xtarget = x_abs
        with_clip = rng.random() < 0.75
        argv = ["fit"] + ([spell(clip_abs, rng.choice(["rel", "abs", "dotrel"]))] if with_clip else []) + \
            ["--segments", spell(seg_abs, rng.choice(["rel", "abs"])), "--model", "sa", "--budget", "20",
             "-q", "-o", x]
        if rng.random() < 0.3:
            argv += ["--per", "clip"] if with_clip else ["--per", "person"]
        text = seg_text(rows)

        def setup(c=c, text=text, seg_abs=seg_abs, x_abs=x_abs):
            for cl in clips:
                copy_clip(cl, os.path.join(c, "data", cl))
            w(seg_abs, text)
            os.symlink(os.path.join(c, "data"), os.path.join(c, "dlink"))
            os.symlink(x_abs, os.path.join(c, "xlink.bvh"))
            os.link(x_abs, os.path.join(c, "xhard.bvh"))
        # -o a hard link or a symlink to the clip: an atomic write replaces the link, not the clip
        expect = "any" if xkind in ("hardlink", "filelink") else "refuse"
        cases.append(Case(fam, "S in %s (%s paths), cwd %s, CLIP %s, -o %s (%s)" % (
            seg_loc, seg_paths, cwd_kind, clips[first] if with_clip else "-", x, xkind),
            argv, cwd, setup=setup, inputs=[os.path.join(c, "data"), seg_abs],
            expect=expect, hints=[os.path.basename(x), x, "-o"], case_dir=c, nowrite_dirs=[c] if expect == "refuse" else []))
    return cases


# ----------------------------------------------------------------------------- family 5


def run_sigint(case):
    res = Res()
    delay = case.extra["delay"]
    double = case.extra.get("double")
    t0 = time.monotonic()
    p = spawn(case.argv, case.cwd)
    try:
        p.wait(timeout=delay)
        res.notes.append("finished before the signal (%.2fs)" % (time.monotonic() - t0))
        res.extra["interrupted"] = False
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGINT)
        ts = time.monotonic()
        res.extra["interrupted"] = True
        if double:
            time.sleep(0.2)
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGINT)
        try:
            p.wait(timeout=STOP_WITHIN)
            res.extra["stop"] = time.monotonic() - ts
        except subprocess.TimeoutExpired:
            res.extra["stop"] = None
            os.killpg(p.pid, signal.SIGKILL)
            p.wait()
            res.we_signalled = True
            res.ended_by_itself = False
            res.timed_out = True
    res.out = p.stdout.read()
    res.err = p.stderr.read()
    p.stdout.close()
    p.stderr.close()
    res.rc = p.returncode
    if res.rc == -signal.SIGINT:  # died of the signal itself: it did stop
        res.we_signalled = True
    res.wall = time.monotonic() - t0
    return res


def fam_sigint(rng, n):
    fam = "5_sigint"
    cases = []
    kinds = ["fit_refine", "fit_field", "fit_outdir", "compare"]
    for i in range(n):
        c = DIRS.new(fam)
        kind = kinds[i % len(kinds)]
        threads = rng.choice([None, "1", "2"])
        single = None
        if kind == "fit_refine":
            single = os.path.join(c, "out.json")
            argv = ["fit", ds("p01"), "--model", "sd", "--budget", "200", "--refine", "100000", "-q", "-o", single]
            if rng.random() < 0.3:
                argv += ["--checkpoint", os.path.join(c, "fit.ckpt")]
        elif kind == "fit_field":
            single = os.path.join(c, "field.json")
            argv = ["fit", ds("p01"), "--model", "sc", "--budget", "300", "--field", "-q", "-o", single]
        elif kind == "fit_outdir":
            argv = ["fit", ds("p01"), "--model", "sd", "--budget", "300", "--per", "clip", "-q",
                    "--out-dir", os.path.join(c, "out")]
        else:
            argv = ["compare", ds("p01"), "--models", "sa,sc", "--optimizers", "svd", "--budget", "300",
                    "-q", "-o", os.path.join(c, "cmp")]
        if threads:
            argv += ["--threads", threads]
        delay = rng.uniform(0.02, 2.2)
        double = rng.random() < 0.15

        def setup(c=c):
            os.makedirs(c)

        def post(case, res, single=single, kind=kind):
            f = []
            if not res.extra.get("interrupted"):
                return f
            stop = res.extra.get("stop")
            if stop is None:
                return [("hang", "did not stop within %gs of Ctrl-C" % STOP_WITHIN)]
            if res.rc == 0:
                if stop > 1.0:
                    f.append(("hang", "ignored Ctrl-C: ran on %.1fs and exited 0" % stop))
                return f
            err = res.err.decode(errors="replace")
            if single and os.path.exists(single):
                f.append(("debris", "interrupted (exit %s) but %s was written" % (res.rc, os.path.basename(single))))
            if res.rc > 0 and "interrupt" not in err.lower():
                f.append(("bad_message", "exit %d after Ctrl-C without saying it was interrupted" % res.rc))
            if kind == "fit_outdir":
                for base, _d, fn in os.walk(os.path.join(case.case_dir, "out")):
                    for x in fn:
                        if x.endswith(".json") and not x.startswith("."):
                            try:
                                json.load(open(os.path.join(base, x)))
                            except Exception as e:
                                f.append(("debris", "partial result %s does not parse: %r" % (x, e)))
            return f
        cs = Case(fam, "%s Ctrl-C at %.2fs%s%s" % (kind, delay, " twice" if double else "",
                                                  " threads=%s" % threads if threads else ""),
                  argv, c, setup=setup, expect="any", runner=run_sigint, post=post, case_dir=c,
                  inputs=[], timeout=60)
        cs.extra = {"delay": delay, "double": double}
        cases.append(cs)
    return cases


# ----------------------------------------------------------------------------- family 6


def fam_dof_names(rng, n_sizes):
    fam = "6_dof_names"
    cases = []
    sizes = sorted(set(int(round(10 * math.exp(math.log(30000) * k / (n_sizes - 1)))) for k in range(n_sizes)))
    if 300000 not in sizes:
        sizes[-1] = 300000
    if sizes[0] != 10:
        sizes[0] = 10
    base = json.load(open(os.path.join(FIX, "p_sc.json")))  # S_C: one gain per DoF
    field = json.load(open(os.path.join(FIX, "field.json")))
    chain = base["dof_names"]
    folder = os.path.join(FIX, "dof")
    os.makedirs(folder, exist_ok=True)
    consumers = ["synthesize", "reach", "style", "synth", "plan"]
    for N in sizes:
        layout = rng.choice(["plain", "superset", "values-only-s", "long"])
        names = ["d%d" % k for k in range(N)]
        if layout == "superset":
            names = chain + names[len(chain):]
        if layout == "long":
            names = ["dof_%s_%d" % ("x" * 12, k) for k in range(N)]
        pfile = os.path.join(folder, "n%d.json" % N)
        ffile = os.path.join(folder, "field%d.json" % N)

        def make(N=N, names=names, layout=layout, pfile=pfile, ffile=ffile):
            if os.path.exists(pfile):
                return
            doc = dict(base)
            doc["dof_names"] = names
            if layout == "values-only-s":
                doc["values"] = {"s": 2.0, "o": 1.0}
            else:
                doc["values"] = {"g_" + x: 0.5 for x in names}
                doc["values"].update({"s": 2.0, "o": 1.0})
            text = json.dumps(doc)
            if len(text) > LIMIT_16:
                doc["values"] = {"s": 2.0, "o": 1.0}
                text = json.dumps(doc)
            w(pfile, text)
            fd = dict(field)
            fd["dof_names"] = names
            w(ffile, json.dumps(fd))
        for cons in consumers + ["synthesize-field", "reach-field"]:
            c = DIRS.new(fam)
            pf = ffile if cons.endswith("field") else pfile
            cname = cons.split("-")[0]
            if cname == "synthesize":
                argv = ["synthesize", ds("p01/r01.bvh"), "--params", pf, "-q", "-o", os.path.join(c, "o.bvh")]
            elif cname == "reach":
                argv = ["reach", "--target", "0.3,1.1,0.4", "--params", pf, "-q", "-o", os.path.join(c, "o.bvh")]
            elif cname == "style":
                argv = ["style", ds("p01/r01.bvh"), "--params", pf, "-q"] + (["-o", os.path.join(c, "st")] if N % 2 else [])
            elif cname == "synth":
                argv = ["synth", "--params", pf, "--persons", "1", "--reaches", "1", "-q", "-o", os.path.join(c, "syn")]
            else:
                argv = ["plan", "--scene", os.path.join(FIX, "bookshelf", "scene.json"), "--target",
                        "-0.25,1.1,0.3", "--budget-ms", "200", "--params", pf, "-q", "-o", os.path.join(c, "o.bvh")]

            def setup(c=c, make=make):
                make()
                os.makedirs(c)
            cases.append(Case(fam, "%s with %d DoF names (%s)" % (cons, N, layout), argv, c, setup=setup,
                              inputs=[pf], expect="refuse", hints=[os.path.basename(pf)], slow=SLOW,
                              case_dir=c, timeout=60, nowrite=[os.path.join(c, "o.bvh")]))
    return cases


# ----------------------------------------------------------------------------- family 7

NUM_RE = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")
NONFIN_RE = re.compile(r"^[+-]?(inf|infinity|nan)$", re.I)


def target_expect(v, base, pos, from_shoulder=False):
    """refuse | run | any for a target with coordinate(s) replaced by v. Targets are checked
    against 10 m from the origin (reach, plan) or from the arm's shoulder (fit, compare,
    synthesize): the shoulder is somewhere in x, z within 0.5 m of the origin, y 1.0..1.7 m."""
    s = v
    if NONFIN_RE.match(s):
        return "refuse"
    if not NUM_RE.match(s):
        return "any"
    x = float(s)
    if not math.isfinite(x):
        return "refuse"
    coords = list(base)
    if pos == "all":
        coords = [x, x, x]
    else:
        coords[pos] = x
    if max(abs(t) for t in coords) > 1e3:
        return "refuse"
    if from_shoulder:
        lo, hi = (-0.5, 1.0, -0.5), (0.5, 1.7, 0.5)
        near = [min(max(t, a), b) for t, a, b in zip(coords, lo, hi)]
        dmin = math.sqrt(sum((t - n) ** 2 for t, n in zip(coords, near)))
        far = [a if abs(t - a) > abs(t - b) else b for t, a, b in zip(coords, lo, hi)]
        dmax = math.sqrt(sum((t - n) ** 2 for t, n in zip(coords, far)))
    else:
        dmin = dmax = math.sqrt(sum(t * t for t in coords))
    if dmin > 10.3:
        return "refuse"
    if dmax < 2.0:
        return "run"
    return "any"


def fam_targets(rng, n):
    fam = "7_targets"
    cases = []
    values = ["1e308", "-1e308", "1e155", "1e6", "11", "1e-300", "nan", "inf", "-inf", "NaN", "Infinity",
              "1e309", "-1e309", "+inf", "1e+308", "-0", "0", "10.5", "9.99", "1e-320", "1" + "0" * 300,
              "0." + "0" * 299 + "1", "1e-400", "12.0", "-11", "0.3", "1E3", "0x10", "1_000"]
    surfaces = ["fit_seg", "compare_seg", "field_seg", "synthesize", "reach", "plan", "relocate"]
    seg3 = read_segments(os.path.join(FIX, "seg_tgt3.csv"))
    combos = [(v, pos, s) for v in values for pos in (0, 1, 2, "all") for s in surfaces]
    for v, pos, surf in sample(rng, combos, n):
        c = DIRS.new(fam)
        echo = [v]
        scan = [os.path.join(c, x) for x in ("out.json", "out.bvh", "cmp", "field.json")]
        nowrite = [os.path.join(c, x) for x in ("out.json", "out.bvh", "field.json")]
        if surf in ("fit_seg", "compare_seg", "field_seg"):
            k = rng.randrange(3)
            rows = []
            for j, r in enumerate(seg3):
                t = [r["target_x"], r["target_y"], r["target_z"]]
                if j == k:
                    if pos == "all":
                        t = [v, v, v]
                    else:
                        t[pos] = v
                rows.append([r["clip"], r["onset"], r["end"], r["arm"], r["label"], r["person"]] + t)
            base = [float(seg3[k]["target_x"]), float(seg3[k]["target_y"]), float(seg3[k]["target_z"])]
            exp = target_expect(v, base, pos, from_shoulder=True)
            text = seg_text(rows, targets=True)

            def setup(c=c, text=text):
                w(os.path.join(c, "seg.csv"), text)
            if surf == "fit_seg":
                argv = ["fit", "--segments", "seg.csv", "--model", "sa", "--budget", "20", "--json", "-o", "out.json"]
            elif surf == "compare_seg":
                argv = ["compare", "--segments", "seg.csv", "--models", "sa", "--optimizers", "svd",
                        "--no-baselines", "--budget", "20", "--json", "-o", "cmp"]
            else:
                argv = ["fit", "--segments", "seg.csv", "--model", "sa", "--budget", "20", "--field",
                        "--json", "-o", "field.json"]
            hints = ["seg.csv"]
            inputs = [os.path.join(c, "seg.csv")]
        else:
            base = {"synthesize": [-0.13, 0.99, 0.34], "reach": [0.3, 1.1, 0.4], "plan": [-0.25, 1.1, 0.3],
                    "relocate": [-0.22, 1.49, 0.50]}[surf]
            t = ["%g" % x for x in base]
            if pos == "all":
                t = [v, v, v]
            else:
                t[pos] = v
            tv = ",".join(t)
            exp = target_expect(v, base, pos, from_shoulder=(surf == "synthesize"))

            def setup(c=c):
                os.makedirs(c)
            flag = "--to" if surf == "relocate" else "--target"
            if surf == "synthesize":
                argv = ["synthesize", ds("p01/r01.bvh"), "--target", tv, "--json", "-o", "out.bvh"]
            elif surf == "reach":
                argv = ["reach", "--target", tv, "--json", "-o", "out.bvh"]
            elif surf == "plan":
                argv = ["plan", "--scene", os.path.join(FIX, "bookshelf", "scene.json"), "--target", tv,
                        "--budget-ms", "200", "--json", "-o", "out.bvh"]
            else:
                argv = ["plan", "--scene", os.path.join(FIX, "bookshelf", "scene.json"), "--task", "relocate",
                        "--object", "blue_book", "--to", tv, "--budget-ms", "200", "--json", "-o", "out.bvh"]
            hints = [flag]
            inputs = []
            echo.append(tv)
        cases.append(Case(fam, "%s, coordinate %s = %s" % (surf, "xyz"[pos] if pos != "all" else "all",
                                                            v if len(v) < 24 else v[:10] + "...(%d chars)" % len(v)),
                          argv, c, setup=setup, inputs=inputs, expect=exp, hints=hints, echo=echo,
                          scan=scan, nowrite=nowrite, case_dir=c))
    return cases


# ----------------------------------------------------------------------------- family 8

WEIRD = ["new\nline", "pi|pe", "back`tick", "#hash", "  lead", "com,ma", 'qu"ote', "tab\tbed", "ünï©ødé"]


def json_mutations(text, kind, rng):
    """[(label, bytes, expectation)] for a JSON document of this kind."""
    doc = json.loads(text)
    out = []
    b = text.encode()
    out.append(("bom", b"\xef\xbb\xbf" + b, "any"))
    out.append(("crlf", text.replace("\n", "\r\n").encode(), "any"))
    out.append(("cr-only", text.replace("\n", "\r").encode(), "any"))
    out.append(("empty", b"", "refuse"))
    out.append(("whitespace-only", b" \n\t\n", "refuse"))
    for k in range(4):
        cut = rng.randrange(1, len(b) - 2)
        tb = b[:cut]
        try:
            json.loads(tb)
            e = "any"
        except Exception:
            e = "refuse"
        out.append(("truncated@%d/%d" % (cut, len(b)), tb, e))
    idx = text.rindex("}")
    pad_under = LIMIT_16 - 1 - len(b)
    out.append(("16MiB-1", (text[:idx] + " " * pad_under + text[idx:]).encode(), "any"))
    out.append(("16MiB+1", (text[:idx] + " " * (pad_under + 2) + text[idx:]).encode(), "refuse"))
    out.append(("deep-nesting", (text[:text.index("{") + 1] + '"zz": ' + "[" * 100000 + "]" * 100000 + "," +
                                 text[text.index("{") + 1:]).encode(), "refuse"))
    k1 = re.search(rb'"([a-z_]{3,})":', b)
    assert k1
    out.append(("invalid-utf8 in key %s" % k1.group(1).decode(),
                b[:k1.start(1) + 2] + b"\xff\xfe" + b[k1.start(1) + 2:], "refuse"))
    out.append(("nul-byte in key %s" % k1.group(1).decode(), b[:k1.start(1) + 2] + b"\x00" + b[k1.start(1) + 2:], "refuse"))
    sv = re.search(rb'": "([a-z_]{3,})"', b)
    if sv:
        out.append(("invalid-utf8 in value %s" % sv.group(1).decode(),
                    b[:sv.start(1) + 1] + b"\xc3\x28" + b[sv.start(1) + 1:], "refuse"))
    out.append(("unknown-key", (text[:text.index("{") + 1] + '"zz_unknown": 1,' + text[text.index("{") + 1:]).encode(), "any"))
    if kind in ("params",):
        vals = doc["values"]
        k0 = next(iter(vals))
        s_same = text.replace('"%s": ' % k0, '"%s": %r,\n    "%s": ' % (k0, vals[k0], k0), 1)
        s_diff = text.replace('"%s": ' % k0, '"%s": 0.123,\n    "%s": ' % (k0, k0), 1)
        assert s_same != text and s_diff != text
        out.append(("dup-values-key-same", s_same.encode(), "any"))
        out.append(("dup-values-key-diff", s_diff.encode(), "refuse"))
        for wname in rng.sample(WEIRD, 5):
            d2 = json.loads(text)
            d2["dof_names"][rng.randrange(len(d2["dof_names"]))] = wname
            out.append(("dof-name %r" % wname, json.dumps(d2, indent=2).encode(), "refuse"))
        for wname in rng.sample(WEIRD, 3):
            d2 = json.loads(text)
            d2["values"]["g_" + wname] = 1.0
            out.append(("values-key %r" % wname, json.dumps(d2, indent=2).encode(), "refuse"))
        d2 = json.loads(text)
        d2["values"] = list(d2["values"].values())
        out.append(("values-as-array", json.dumps(d2).encode(), "refuse"))
        d2 = json.loads(text)
        del d2["values"]
        out.append(("no-values", json.dumps(d2).encode(), "refuse"))
    if kind == "field":
        assert '"model": "sa",' in text
        out.append(("dup-key-model-diff", text.replace('"model": "sa",', '"model": "sa",\n  "model": "sc",', 1).encode(), "refuse"))
        d2 = json.loads(text)
        d2["names"] = [rng.choice(WEIRD)]
        out.append(("names-weird", json.dumps(d2, indent=1).encode(), "refuse"))
        d2 = json.loads(text)
        d2["samples"] = []
        out.append(("no-samples", json.dumps(d2).encode(), "refuse"))
        d2 = json.loads(text)
        d2["samples"][0]["values"] = [1.0, 2.0, 3.0]
        out.append(("sample-values-wrong-length", json.dumps(d2).encode(), "refuse"))
    if kind == "scene":
        assert '"position": [-0.25, 1.11, 0.50],' in text
        out.append(("dup-key-position-diff", text.replace('"position": [-0.25, 1.11, 0.50],',
                                                          '"position": [-0.25, 1.11, 0.50], "position": [0, 0, 0],', 1).encode(), "refuse"))
        d2 = json.loads(text)
        d2["objects"] = []
        out.append(("no-objects", json.dumps(d2).encode(), "any"))
        d2 = json.loads(text)
        d2["objects"].append(dict(d2["objects"][2]))
        out.append(("duplicate-object-name", json.dumps(d2).encode(), "refuse"))
        d2 = json.loads(text)
        for o in d2["objects"]:
            if o.get("shape", {}).get("type") == "mesh":
                o["shape"]["file"] = "/dev/zero"
        out.append(("mesh-file-/dev/zero", json.dumps(d2).encode(), "refuse"))
        d2 = json.loads(text)
        for o in d2["objects"]:
            if o.get("shape", {}).get("type") == "mesh":
                o["shape"]["file"] = "missing.obj"
        out.append(("mesh-file-missing", json.dumps(d2).encode(), "refuse"))
        d2 = json.loads(text)
        d2["objects"][1]["shape"]["file"] = "../../../../../../../../etc/hostname"
        out.append(("mesh-file-not-obj", json.dumps(d2).encode(), "refuse"))
    # number literals
    nums = [m for m in re.finditer(r"(?<![\w.\"])-?\d+\.\d+(?:[eE][+-]?\d+)?", text)]
    for k in range(6):
        if not nums:
            break
        m = rng.choice(nums)
        rep = rng.choice(["1e999", "-1e999", "1e308", "NaN", "null", "true", '"1"', "-0", "1e-400",
                          "123456789012345678901234567890123", "Infinity", "[]"])
        mt = text[:m.start()] + rep + text[m.end():]
        try:
            json.loads(mt)
            e = "any"
        except Exception:
            e = "refuse"
        if rep in ("NaN", "Infinity"):
            e = "refuse"  # not JSON
        out.append(("number@%d->%s" % (m.start(), rep), mt.encode(), e))
    for k in range(3):
        bb = bytearray(b)
        for _ in range(rng.randint(1, 4)):
            bb[rng.randrange(len(bb))] = rng.choice(b"{}[],:\"0123456789-eE.axz \n")
        try:
            json.loads(bytes(bb))
            e = "any"
        except Exception:
            e = "refuse"
        out.append(("byte-flips#%d" % k, bytes(bb), e))
    return out


def csv_mutations(text, rng, c):
    """[(label, bytes, expectation, extra_files)] for a segments file (rows with targets)."""
    out = []
    b = text.encode()
    lines = text.split("\n")
    out.append(("bom", b"\xef\xbb\xbf" + b, "any", {}))
    out.append(("crlf", text.replace("\n", "\r\n").encode(), "any", {}))
    out.append(("cr-only", text.replace("\n", "\r").encode(), "any", {}))
    out.append(("empty", b"", "refuse", {}))
    out.append(("header-only", (lines[0] + "\n" + lines[1] + "\n").encode(), "refuse", {}))
    for k in range(4):
        cut = rng.randrange(1, len(b) - 2)
        out.append(("truncated@%d/%d" % (cut, len(b)), b[:cut], "any", {}))
    pad = LIMIT_16 - 1 - len(b)
    out.append(("16MiB-1 (comment)", (text + "#" + "x" * (pad - 2) + "\n").encode(), "any", {}))
    out.append(("16MiB+1 (comment)", (text + "#" + "x" * (pad) + "\n").encode(), "refuse", {}))
    out.append(("dup-header-arm", text.replace("arm,label", "arm,arm", 1).encode(), "refuse", {}))
    out.append(("missing-arm-column", "\n".join(
        ",".join(x for j, x in enumerate(l.split(",")) if j != 3) if l and not l.startswith("#") else l
        for l in lines).encode(), "refuse", {}))
    out.append(("short-row", (text.rstrip("\n") + "\n" + lines[2].split(",")[0] + ",7\n").encode(), "refuse", {}))
    out.append(("unbalanced-quote", text.replace(lines[2], '"' + lines[2], 1).encode(), "refuse", {}))
    out.append(("invalid-utf8", text.encode().replace(b",reach,", b",re\xffach,", 1), "any", {}))
    out.append(("nul-byte", text.encode().replace(b",reach,", b",re\x00ach,", 1), "any", {}))
    for fr in ["-1", "7.5", "1e30", "99999999999999999999", "71", "0x10", ""]:
        parts = lines[2].split(",")
        parts[1] = fr
        e = "refuse"
        out.append(("onset=%r" % fr, text.replace(lines[2], ",".join(parts), 1).encode(), e, {}))
    for col, opts in ((5, WEIRD), (4, WEIRD)):
        for wname in rng.sample(opts, 3):
            rows = list(csv.reader(io.StringIO("\n".join(l for l in lines if not l.startswith("#")))))
            for r in rows[1:]:
                if r:
                    r[col] = wname if rng.random() < 0.7 else r[col]
            out.append(("%s=%r" % ("person" if col == 5 else "label", wname),
                        seg_text([r for r in rows[1:] if r], targets=True, header=rows[0]).encode(), "any", {}))
    for wname in rng.sample(WEIRD, 4):
        rows = list(csv.reader(io.StringIO("\n".join(l for l in lines if not l.startswith("#")))))
        fname = wname + ".bvh"
        rows[1][0] = fname if not fname.startswith(" ") else "./" + fname
        out.append(("clip named %r" % fname, seg_text([r for r in rows[1:] if r], targets=True, header=rows[0]).encode(),
                    "any", {fname: ds("p01/r01.bvh")}))
    rows = list(csv.reader(io.StringIO("\n".join(l for l in lines if not l.startswith("#")))))
    rows[1][0] = "lead.bvh"
    out.append(("clip ' lead.bvh' vs 'lead.bvh' (leading space trimmed?)",
                seg_text([["  lead.bvh"] + rows[1][1:]], targets=True, header=rows[0]).encode(), "any",
                {"lead.bvh": ds("p02/r05.bvh"), "  lead.bvh": ds("p01/r01.bvh")}))
    for k in range(3):
        bb = bytearray(b)
        for _ in range(rng.randint(1, 4)):
            bb[rng.randrange(len(bb))] = rng.choice(b",\"\n0123456789-.x ")
        out.append(("byte-flips#%d" % k, bytes(bb), "any", {}))
    return out


def fam_mutations(rng, scale):
    fam = "8_mutations"
    cases = []
    docs = {
        "params": open(os.path.join(FIX, "p_sa.json")).read(),
        "field": open(os.path.join(FIX, "field.json")).read(),
        "scene": open(os.path.join(FIX, "bookshelf", "scene.json")).read(),
    }
    consumers = {
        "params": ["synthesize", "reach", "style", "synth", "plan"],
        "field": ["synthesize", "reach", "style"],
        "scene": ["plan", "animate"],
        "segments": ["fit", "compare", "fit_outdir"],
    }
    items = []
    for kind in ("params", "field", "scene"):
        for lab, data, exp in json_mutations(docs[kind], kind, rng):
            for cons in consumers[kind]:
                items.append((kind, lab, data, exp, cons, {}))
    segtext = open(os.path.join(FIX, "seg_tgt3.csv")).read()
    # clips relative to the segments file, in the case folder
    rows = read_segments(os.path.join(FIX, "seg_tgt3.csv"))
    rel = seg_text([[os.path.relpath(r["clip"], os.path.join(FIX, "ds")).replace("p01/", "clips/"), r["onset"], r["end"],
                     r["arm"], r["label"], r["person"], r["target_x"], r["target_y"], r["target_z"]] for r in rows],
                   targets=True)
    for lab, data, exp, extra in csv_mutations(rel, rng, None):
        for cons in consumers["segments"]:
            items.append(("segments", lab, data, exp, cons, extra))
    if scale < 1.0:
        items = sample(rng, items, max(12, int(len(items) * scale)))
    for kind, lab, data, exp, cons, extra in items:
        c = DIRS.new(fam)
        fname = {"params": "params.json", "field": "field.json", "scene": "scene.json", "segments": "seg.csv"}[kind]
        path = os.path.join(c, fname)
        weird_names = [x for x in WEIRD if x in lab or repr(x) in lab]

        def setup(c=c, data=data, path=path, kind=kind, extra=extra):
            os.makedirs(c)
            w(path, data)
            if kind == "scene":
                shutil.copy(os.path.join(FIX, "bookshelf", "shelf.obj"), os.path.join(c, "shelf.obj"))
            if kind == "segments":
                for cl in ("p01/r01.bvh", "p01/r02.bvh", "p01/r03.bvh"):
                    copy_clip(cl, os.path.join(c, cl.replace("p01/", "clips/")))
            for name, src in extra.items():
                shutil.copy(src, os.path.join(c, name))
        outs = [os.path.join(c, x) for x in ("o.bvh", "o.json", "syn", "cmp", "fo", "a.gif", "a.png", "st")]
        if kind in ("params", "field"):
            if cons == "synthesize":
                argv = ["synthesize", ds("p01/r01.bvh"), "--params", fname, "--json", "-o", "o.bvh"]
            elif cons == "reach":
                argv = ["reach", "--target", "0.3,1.1,0.4", "--params", fname, "--json", "-o", "o.bvh"]
            elif cons == "style":
                argv = ["style", ds("p01/r01.bvh"), "--params", fname, "--json"] + (["-o", "st"] if rng.random() < 0.5 else [])
            elif cons == "synth":
                argv = ["synth", "--params", fname, "--persons", "1", "--reaches", "1", "-o", "syn"]
            else:
                argv = ["plan", "--scene", os.path.join(FIX, "bookshelf", "scene.json"), "--target", "-0.25,1.1,0.3",
                        "--budget-ms", "200", "--params", fname, "--json", "-o", "o.bvh"]
        elif kind == "scene":
            if cons == "plan":
                argv = ["plan", "--scene", fname, "--target", "-0.25,1.1,0.3", "--budget-ms", "200", "--json", "-o", "o.bvh"]
            else:
                argv = ["animate", os.path.join(FIX, "plan.bvh"), "--scene", fname, "--size", "64x64", "--fps", "4",
                        "--strip-frames", "1", "-q", "-o", "a.gif"]
        else:
            if cons == "fit":
                argv = ["fit", "--segments", fname, "--model", "sa", "--budget", "20", "--json", "-o", "o.json"]
            elif cons == "compare":
                argv = ["compare", "--segments", fname, "--models", "sa", "--optimizers", "svd", "--no-baselines",
                        "--budget", "20", "-q", "-o", "cmp"]
            else:
                argv = ["fit", "--segments", fname, "--model", "sa", "--budget", "20", "--per", "clip", "-q",
                        "--out-dir", "fo"]
        if kind == "segments" and ("person=" in lab or "clip named" in lab) and cons == "compare" and rng.random() < 0.5:
            argv += ["--per", "person", "--holdout", "1"]
        hints = [fname]
        if "--holdout" in argv:
            hints.append("--holdout")
        if "16MiB+1" in lab:
            hints.append("16 MiB")

        def post(case, res, weird_names=weird_names, outs=outs):
            f = []
            if res.rc != 0:
                return f
            for p, text in scan_paths(outs):
                if p.endswith(".md"):
                    for prob in md_table_problems(text):
                        f.append(("wrong_exit0", "%s: %s" % (os.path.relpath(p, case.case_dir), prob)))
                    for wn in weird_names:
                        if "\n" in wn and wn in text:
                            f.append(("wrong_exit0", "%s: a name with a raw newline breaks the Markdown" % os.path.relpath(p, case.case_dir)))
                        if "`" in wn and ("`%s`" % wn) in text:
                            f.append(("wrong_exit0", "%s: name %r in a single-backtick code span (broken)" % (os.path.relpath(p, case.case_dir), wn)))
                if p.endswith(".csv"):
                    rows = csv_rows(p)
                    widths = set(len(r) for r in rows if r and not r[0].startswith("#"))
                    if len(widths) > 1:
                        f.append(("wrong_exit0", "%s: rows of different widths %s" % (os.path.relpath(p, case.case_dir), sorted(widths))))
            return f
        cases.append(Case(fam, "%s %s -> %s" % (kind, lab, cons), argv, c, setup=setup, inputs=[path] + [os.path.join(c, n) for n in extra],
                          expect=exp, hints=hints, scan=outs, post=post, case_dir=c, timeout=60,
                          nowrite=[os.path.join(c, "o.bvh"), os.path.join(c, "o.json"), os.path.join(c, "a.gif")]))
    return cases


# ----------------------------------------------------------------------------- family 9


def fam_sigkill(rng, n):
    fam = "9_sigkill"
    cases = []
    for i in range(n):
        c = DIRS.new(fam)
        variant = rng.choice(["kill", "kill", "kill", "kill-nested", "planted", "planted-nested", "kill-single",
                              "kill-compare"])
        threads = rng.choice([None, "1", "2"])
        if variant.endswith("nested"):
            clips_arg = [ds("p01"), ds("p02/r01.bvh"), ds("p02/r02.bvh"), ds("p02/r03.bvh")]
            names = ["p01/r%02d.bvh.json" % k for k in range(1, 15)] + ["p02/r01.bvh.json", "p02/r02.bvh.json",
                                                                         "p02/r03.bvh.json"]
        else:
            clips_arg = [ds("p01")]
            names = ["r%02d.bvh.json" % k for k in range(1, 15)]
        out = os.path.join(c, "out")
        if variant == "kill-single":
            argv = ["fit", ds("p01"), "--model", "sd", "--budget", "300", "-q", "-o", os.path.join(c, "single.json")]
        elif variant == "kill-compare":
            argv = ["compare", ds("p01"), "--models", "sa,sc", "--optimizers", "svd", "--budget", "400", "-q", "-o", out]
        else:
            outflag = ["--out-dir", out] if rng.random() < 0.7 else ["-o", out + "/"]
            argv = ["fit"] + clips_arg + ["--model", rng.choice(["sc", "sd"]), "--budget", "300", "--per", "clip", "-q"] + outflag
        if threads:
            argv += ["--threads", threads]
        delay = rng.uniform(0.02, 1.4)
        plant = [(rng.choice(names), rng.randint(0, 3)) for _ in range(rng.randint(1, 4))] \
            if variant.startswith("planted") else []
        pre_existing = rng.random() < 0.3

        def runner(case, delay=delay, plant=plant, argv=argv, variant=variant, out=out, pre_existing=pre_existing):
            res = Res()
            os.makedirs(case.case_dir, exist_ok=True)
            if pre_existing:
                os.makedirs(out, exist_ok=True)
            t0 = time.monotonic()
            if not variant.startswith("planted"):
                p = spawn(argv, case.cwd)
                try:
                    p.wait(timeout=delay)
                    res.notes.append("first run finished before the kill")
                except subprocess.TimeoutExpired:
                    os.killpg(p.pid, signal.SIGKILL)
                    p.wait()
                p.communicate()
                res.extra["tmp_after_kill"] = len(tmp_debris(case.case_dir))
            else:
                for name, k in plant:
                    d, b = os.path.split(os.path.join(out, name))
                    os.makedirs(d, exist_ok=True)
                    w(os.path.join(d, ".%s.%d.%d.tmp" % (b, DEAD_PID, k)), b'{"partial": ')
                res.extra["tmp_after_kill"] = len(tmp_debris(case.case_dir))
            p = spawn(argv, case.cwd)
            try:
                res.out, res.err = p.communicate(timeout=case.timeout)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                res.out, res.err = p.communicate()
                res.timed_out = True
                res.ended_by_itself = False
            res.rc = p.returncode
            res.wall = time.monotonic() - t0
            return res

        def post(case, res, names=names, variant=variant, out=out):
            f = []
            if res.rc != 0:
                return f
            if variant == "kill-single":
                try:
                    json.load(open(os.path.join(case.case_dir, "single.json")))
                except Exception as e:
                    f.append(("wrong_exit0", "single.json does not parse: %r" % e))
                return f
            if variant == "kill-compare":
                rows = csv_rows(os.path.join(out, "results.csv")) if os.path.exists(os.path.join(out, "results.csv")) else []
                if len(rows) < 2 or len(set(len(r) for r in rows)) != 1:
                    f.append(("wrong_exit0", "results.csv after the complete run: %d rows" % len(rows)))
                return f
            for name in names:
                p = os.path.join(out, name)
                try:
                    json.load(open(p))
                except Exception as e:
                    f.append(("wrong_exit0", "%s after the complete run: %r" % (name, e)))
            return f
        cases.append(Case(fam, "%s at %.2fs%s%s" % (variant, delay, " threads=%s" % threads if threads else "",
                                                   " planted %s" % [".%s.%s.%d.tmp" % (x, "DEADPID", k) for x, k in plant]
                                                   if plant else ""),
                          argv, c, runner=runner, expect="success", post=post, case_dir=c, timeout=60,
                          repro=("kill -9 the first run after %.2fs, then run it again" % delay) if not plant else
                          "plant the stale temporaries (dead pid) in out/, then run it"))
    return cases


# ----------------------------------------------------------------------------- family 10


def fam_weird_paths(rng, n):
    fam = "10_weird_paths"
    cases = []
    wd = os.path.join(FIX, "weird")
    paths = {
        "fifo": os.path.join(wd, "fifo"), "symlink-loop": os.path.join(wd, "loop1"),
        "dangling-symlink": os.path.join(wd, "dangling.bvh"), "missing-file": os.path.join(wd, "missing.bvh"),
        "missing-folder": os.path.join(wd, "missing-folder/"), "empty-folder": os.path.join(wd, "emptydir"),
        "folder-txt-only": os.path.join(wd, "txtdir"), "folder-with-folder-a.bvh": os.path.join(wd, "bvhdir"),
        "folder-with-fifo-a.bvh": os.path.join(wd, "fifodir"), "folder-with-loop-a.bvh": os.path.join(wd, "loopdir"),
        "folder-with-dangling-a.bvh": os.path.join(wd, "dangdir"), "folder-self-loop": os.path.join(wd, "selfloopdir"),
        "/dev/zero": "/dev/zero", "/dev/null": "/dev/null", "/dev/stdin": "/dev/stdin",
        "/proc/self/status": "/proc/self/status", "file-with-slash": ds("p01/r01.bvh") + "/",
        "name-too-long": os.path.join(wd, "a" * 300 + ".bvh"), "empty-string": "",
    }
    cmds = ["inspect", "convert", "segment", "fit", "fit_outdir", "compare", "synthesize", "animate", "style",
            "plot", "style--params", "synthesize--params", "reach--params", "reach--person", "synth--params",
            "fit--segments", "compare--segments", "plan--scene", "animate--scene", "animate--report",
            "plan--params", "fit--checkpoint"]
    combos = [(k, cmd) for k in paths for cmd in cmds]
    for kind, cmd in sample(rng, combos, n):
        c = DIRS.new(fam)
        X = paths[kind]
        o = lambda name: os.path.join(c, name)
        P = os.path.join(FIX, "p_sa.json")
        clip = ds("p01/r01.bvh")
        scene = os.path.join(FIX, "bookshelf", "scene.json")
        argv = {
            "inspect": ["inspect", X],
            "convert": ["convert", X, "-o", o("o.bvh")],
            "segment": ["segment", X, "--manifest", o("s.csv")],
            "fit": ["fit", X, "--model", "sa", "--budget", "20", "-o", o("o.json")],
            "fit_outdir": ["fit", X, "--model", "sa", "--budget", "20", "--per", "clip", "--out-dir", o("fo")],
            "compare": ["compare", X, "--models", "sa", "--optimizers", "svd", "--budget", "20", "-o", o("cmp")],
            "synthesize": ["synthesize", X, "-o", o("o.bvh")],
            "animate": ["animate", X, "-o", o("a.gif"), "--size", "64x64"],
            "style": ["style", X, "--params", P, "-o", o("st")],
            "plot": ["plot", "speed", X, "-o", o("s.svg")],
            "style--params": ["style", clip, "--params", X, "-o", o("st")],
            "synthesize--params": ["synthesize", clip, "--params", X, "-o", o("o.bvh")],
            "reach--params": ["reach", "--target", "0.3,1.1,0.4", "--params", X, "-o", o("o.bvh")],
            "reach--person": ["reach", "--target", "0.3,1.1,0.4", "--person", X, "-o", o("o.bvh")],
            "synth--params": ["synth", "--params", X, "--persons", "1", "--reaches", "1", "-o", o("syn")],
            "fit--segments": ["fit", "--segments", X, "--model", "sa", "--budget", "20", "-o", o("o.json")],
            "compare--segments": ["compare", "--segments", X, "--models", "sa", "--budget", "20", "-o", o("cmp")],
            "plan--scene": ["plan", "--scene", X, "--target", "-0.25,1.1,0.3", "-o", o("o.bvh")],
            "animate--scene": ["animate", os.path.join(FIX, "plan.bvh"), "--scene", X, "-o", o("a.gif"), "--size", "64x64"],
            "animate--report": ["animate", os.path.join(FIX, "plan.bvh"), "--scene", scene, "--report", X, "-o", o("a.gif"),
                                "--size", "64x64"],
            "plan--params": ["plan", "--scene", scene, "--target", "-0.25,1.1,0.3", "--params", X, "-o", o("o.bvh")],
            "fit--checkpoint": ["fit", clip, "--model", "sa", "--budget", "20", "--checkpoint", X, "--resume", "-o", o("o.json")],
        }[cmd]
        argv = argv + ["-q"]

        def setup(c=c):
            os.makedirs(c)
        hint = X.rstrip("/")
        hints = [hint, os.path.basename(hint)] if X else ["empty", "''", '""', "path", "no such", "a value is required"]
        if kind.startswith("folder-with") or kind == "folder-self-loop":
            hints.append(os.path.basename(hint))
        cases.append(Case(fam, "%s: %s" % (cmd, kind), argv, c, setup=setup, inputs=[wd] if X.startswith(wd) else [],
                          expect="refuse", hints=hints, case_dir=c, timeout=15,
                          nowrite=[o(x) for x in ("o.bvh", "o.json", "s.csv", "a.gif", "s.svg")],
                          nowrite_dirs=[c]))
    return cases


# ----------------------------------------------------------------------------- family 11


def fam_holdout_arms(rng, n):
    fam = "11_holdout_arms"
    cases = []
    for i in range(n):
        c = DIRS.new(fam)
        persons = ["p01"] + rng.sample(["p02", "p03", "p04"], rng.randint(0, 2))
        both_person = rng.choice(persons)
        rows = []
        for p in persons:
            takes = sorted(x for x in CLIPS if x.startswith(p + "/"))
            takes = takes[:rng.randint(4, 14)]
            arms = {}
            for t in takes:
                if p == both_person:
                    arms[t] = rng.choice(["right", "left", "both"])
                else:
                    arms[t] = "right"
            if p == both_person:
                if all(a == "right" for a in arms.values()):
                    arms[takes[-1]] = "left"
                if rng.random() < 0.4:
                    arms[takes[-1]] = "both"
            for t in takes:
                o, e = SEG_MAIN[t]
                for a in (["right", "left"] if arms[t] == "both" else [arms[t]]):
                    rows.append([os.path.join("clips", t), o, e, a, "reach", p])
        k = rng.choice([1, 1, 2, 3])
        who = rng.choice(["segments", "segments", "folder"])
        text = seg_text(rows)
        used = sorted(set(r[0] for r in rows))

        def setup(c=c, text=text, used=used):
            for u in used:
                copy_clip(u[len("clips/"):], os.path.join(c, u))
            w(os.path.join(c, "seg.csv"), text)
        argv = ["compare", "--segments", "seg.csv", "--per", "person", "--holdout", str(k), "--person", who,
                "--models", rng.choice(["sa", "sa,sc"]), "--optimizers", "svd", "--no-baselines", "--budget", "20",
                "-q", "-o", "ho"]

        def post(case, res, k=k):
            f = []
            if res.rc != 0:
                return f
            path = os.path.join(case.cwd, "ho", "holdout.csv")
            if not os.path.exists(path):
                return [("wrong_exit0", "exit 0 but no holdout.csv")]
            rows = csv_rows(path)
            hdr = rows[0]
            body = [r for r in rows[1:] if r]
            if len(set(len(r) for r in rows if r)) > 1:
                f.append(("wrong_exit0", "holdout.csv rows of different widths"))
            di = hdr.index("distance_m") if "distance_m" in hdr else None
            keycols = [j for j, h in enumerate(hdr) if h not in ("distance_m", "seconds")]
            seen = {}
            for r in body:
                if di is not None:
                    try:
                        v = float(r[di])
                        if not math.isfinite(v) or v < 0:
                            f.append(("wrong_exit0", "holdout.csv distance %r" % r[di]))
                    except ValueError:
                        f.append(("wrong_exit0", "holdout.csv distance %r" % r[di]))
                key = tuple(r[j] for j in keycols)
                seen.setdefault(key, []).append(r[di] if di is not None else "")
            dups = [(kk, v) for kk, v in seen.items() if len(v) > 1]
            if dups:
                kk, v = dups[0]
                f.append(("wrong_exit0", "holdout.csv: %d row keys repeat with different results (e.g. %s -> %s): "
                          "held-out reaches of one clip on both arms cannot be told apart (no arm/onset column)"
                          % (len(dups), ",".join(kk[:2]), v)))
            return f
        cases.append(Case(fam, "%d persons, %s on both arms, holdout %d, --person %s, %d rows" % (
            len(persons), both_person, k, who, len(rows)), argv, c, setup=setup,
            inputs=[os.path.join(c, "clips"), os.path.join(c, "seg.csv")], expect="any",
            hints=["seg.csv", "arm", "person"], post=post, case_dir=c, scan=[os.path.join(c, "ho")]))
    return cases


# ----------------------------------------------------------------------------- main

FAMILIES = [
    ("1_outdir_inputs", fam_outdir_inputs, 330, 24),
    ("2_arm_pairs", fam_arm_pairs, 90, 8),
    ("3_scene_mesh", fam_scene_mesh, 160, 12),
    ("4_fit_o_clip", fam_fit_o_clip, 150, 12),
    ("5_sigint", fam_sigint, 64, 8),
    ("6_dof_names", fam_dof_names, 24, 4),
    ("7_targets", fam_targets, 420, 40),
    ("8_mutations", fam_mutations, 1.0, 0.1),
    ("9_sigkill", fam_sigkill, 36, 4),
    ("10_weird_paths", fam_weird_paths, 418, 40),
    ("11_holdout_arms", fam_holdout_arms, 50, 6),
]


def main():
    global K, SCR, FIX, RNG
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--kinergy", default=DEFAULT_KINERGY)
    ap.add_argument("--quick", action="store_true", help="fewer cases per family (a smoke run)")
    ap.add_argument("--only", default="", help="comma-separated family names or numbers")
    ap.add_argument("--scratch", default="/tmp/kinergy-sweep")
    ap.add_argument("--keep", action="store_true", help="keep the folders of ok cases too")
    ap.add_argument("--seed", type=int, default=27)
    ap.add_argument("--summary", default="/tmp/sweep-summary.txt")
    ap.add_argument("--report", default="/tmp/sweep-report.txt")
    ap.add_argument("--cases", default="/tmp/sweep-cases.jsonl")
    a = ap.parse_args()
    K = os.path.abspath(a.kinergy)
    if not os.access(K, os.X_OK):
        sys.exit("no kinergy binary at %s (cargo build --release -p kinergy-cli)" % K)
    SCR = os.path.abspath(a.scratch)
    if not SCR.startswith("/tmp/"):
        sys.exit("--scratch must be under /tmp")
    if os.path.exists(SCR):
        shutil.rmtree(SCR)
    os.makedirs(SCR)
    FIX = os.path.join(SCR, "fix")
    RNG = random.Random(a.seed)
    t_start = time.monotonic()
    repo_before = {p: snap(p) for p in (DATA, BOOKSHELF, TESTDATA)}
    prepare_fixtures()
    fix_before = snap(os.path.join(FIX, "ds"))
    only = [x.strip() for x in a.only.split(",") if x.strip()]
    results = []
    report = open(a.report, "w")
    report.write("kinergy adversarial sweep: non-ok cases (binary %s, seed %d%s)\n\n" % (K, a.seed, ", quick" if a.quick else ""))
    jl = open(a.cases, "w")
    for name, gen, full, quick in FAMILIES:
        if only and not any(name == o or name.split("_")[0] == o for o in only):
            continue
        rng = random.Random("%d:%s" % (a.seed, name))
        cases = gen(rng, quick if a.quick else full)
        t_fam = time.monotonic()
        print("== %s: %d cases" % (name, len(cases)), flush=True)
        for case in cases:
            if case.setup:
                case.setup()
            elif case.case_dir and not case.runner:
                os.makedirs(case.case_dir, exist_ok=True)
            pre_inputs = {p: snap(p) for p in case.inputs if os.path.lexists(p) or p}
            pre_inputs = {p: s for p, s in pre_inputs.items() if s != ("missing",)}
            pre_nowrite = {p: snap(p) for p in case.nowrite}
            pre_tree = {"nowrite_dirs": {d: walk_nofollow(d)[1] for d in case.nowrite_dirs}}
            if case.case_dir:
                pre_tree["dirs"] = walk_nofollow(case.case_dir)[0]
            res = (case.runner or run_plain)(case)
            findings = classify(case, res, pre_inputs, pre_tree, pre_nowrite)
            cls = primary(findings)
            results.append((case.family, cls))
            rec = {"family": case.family, "label": case.label, "class": cls, "findings": findings,
                   "cwd": case.cwd, "argv": case.argv, "exit": res.rc, "wall_s": round(res.wall, 3),
                   "stderr_bytes": len(res.err), "stderr_head": res.err[:200].decode("utf-8", "replace"),
                   "notes": res.notes, "extra": res.extra}
            jl.write(json.dumps(rec, default=str) + "\n")
            if cls != "ok":
                report.write("[%s] %s: %s\n" % (cls, case.family, case.label))
                for fc, fd in findings:
                    report.write("    - %s: %s\n" % (fc, fd))
                report.write("    $ cd %s && %s %s\n" % (shlex.quote(case.cwd), shlex.quote(K), q(case.argv)))
                if case.repro:
                    report.write("      (%s)\n" % case.repro)
                report.write("    exit %s, %.2fs, stderr %d bytes: %r\n\n" % (res.rc, res.wall, len(res.err), res.err[:300]))
                report.flush()
            elif not a.keep and case.case_dir and os.path.isdir(case.case_dir):
                shutil.rmtree(case.case_dir, ignore_errors=True)
        counts = {}
        for fam_, cls in results:
            if fam_ == name:
                counts[cls] = counts.get(cls, 0) + 1
        print("   %s  (%.0fs)" % (", ".join("%s %d" % (k, v) for k, v in sorted(counts.items())), time.monotonic() - t_fam), flush=True)
    # global checks: the repository's data and the shared fixtures are untouched
    glob_findings = []
    for p, s in repo_before.items():
        if snap(p) != s:
            glob_findings.append("repository data changed: %s" % p)
    if snap(os.path.join(FIX, "ds")) != fix_before:
        glob_findings.append("shared fixture clips changed: %s" % os.path.join(FIX, "ds"))
    jl.close()
    # summary
    fams = [f[0] for f in FAMILIES if any(r[0] == f[0] for r in results)]
    lines = []
    hdr = "%-18s %6s " % ("family", "cases") + " ".join("%9s" % c[:9] for c in CLASSES)
    lines.append("kinergy adversarial sweep (seed %d%s), %s, %.0f s" % (a.seed, ", quick" if a.quick else "", K,
                                                                        time.monotonic() - t_start))
    lines.append("")
    lines.append(hdr)
    lines.append("-" * len(hdr))
    tot = {c: 0 for c in CLASSES}
    for fam_ in fams:
        rs = [r for r in results if r[0] == fam_]
        row = "%-18s %6d " % (fam_, len(rs))
        for c in CLASSES:
            n = sum(1 for r in rs if r[1] == c)
            tot[c] += n
            row += "%9s " % (n if n else ".")
        lines.append(row.rstrip())
    lines.append("-" * len(hdr))
    lines.append(("%-18s %6d " % ("total", len(results)) + " ".join("%9s" % (tot[c] if tot[c] else ".") for c in CLASSES)).rstrip())
    lines.append("")
    lines.append("unexpected_fail: a non-zero exit where a normal run was expected (shown apart from ok).")
    lines.append("details of every non-ok case: %s; every case: %s" % (a.report, a.cases))
    if glob_findings:
        lines.append("")
        lines += ["GLOBAL: " + g for g in glob_findings]
        report.write("\nGLOBAL:\n" + "\n".join(glob_findings) + "\n")
    report.close()
    text = "\n".join(lines) + "\n"
    with open(a.summary, "w") as f:
        f.write(text)
    print()
    print(text)
    sys.exit(0 if tot["ok"] == len(results) and not glob_findings else 1)


if __name__ == "__main__":
    main()
