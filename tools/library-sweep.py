#!/usr/bin/env python3
"""Adversarial sweep of Kinergy's library surfaces, after issue 42 (cases 0-11).

A seeded generator (fixed default seed: a re-run tries the same cases) of about 1,600 cases
against `fit --per clip --out-dir`, `--shard`, `--resume`, `collect`, `compare --library`, the
Python package, S_E, `--objective`, `--controller`, `--arm auto`, `segment --world`, kills,
Ctrl-C and odd file systems. Each case runs one or more commands with timeouts in its own
folder under the scratch root (never touching the repository's files or the machine's /dev),
and is classified into one outcome class, the worst of what was seen:

  panic        exit 101, "panicked", a PanicException, or death by a signal we did not send
               (an allocation beyond the address-space limit aborts: a memory blow-up)
  hang         a timeout, or a run that did not stop within 5 s of Ctrl-C
  data_loss    an input changed or removed, a result overwritten by another reach's, or
               `collect` "complete" (exit 0) while a take has no result or a wrong one
               (checked against a one-machine run of the same takes and settings)
  wrong_exit0  exit 0 (or a Python return) where a refusal was expected; an option ignored;
               a wrong number reported; "inf"/"NaN"/a 31+-digit number printed
  bad_message  no message, stderr over 2,000 bytes, a message that names neither the
               offending flag nor file, an internal name (a Rust `Debug` struct,
               `max_evaluations`, `rest_speed`, "File exists (os error 17)"), or a refusal
               of a valid input (its message is misleading by definition)
  clean_error  the expected refusal, with a clear message
  ok           a checked success

Families (case numbers of issue 42): 00 special outputs (0), 01 result names (1), 02 take edits
between shards (2), 03 settings per shard (3), 04 resume spellings (4), 05 links (5),
06 bounds: Slurm variables, --shard, record names (6), 07 Ctrl-C (7), 08 Python strictness
(8), 09 tables (9), 10 ignored options (10), 11 messages (11), 12 kills and odd file systems.

Usage:
  python3 tools/library-sweep.py [--kinergy PATH] [--python PATH] [--no-python] [--quick]
                                 [--only FAMILY,...] [--scratch DIR] [--keep] [--seed N]
Writes /tmp/library-sweep-summary.txt (the table), /tmp/library-sweep-report.txt (every case
not ok or clean_error: commands, exit, stderr head) and /tmp/library-sweep-cases.jsonl (every
case). Runs one process at a time (library fits with --threads 1, except where a case is about
threads). Python 3 standard library only; the Python-package cases run the given interpreter,
which must `import kinergy`. Exit status 0 when every case is ok or clean_error, 1 otherwise.
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
import resource
import shlex
import shutil
import signal
import socket
import stat
import subprocess
import sys
import time

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_KINERGY = os.path.join(REPO, "target", "release", "kinergy")
DEFAULT_PYTHON = os.path.join(REPO, "target", "notebook-venv", "bin", "python")
DATA = os.path.join(REPO, "data-synthetic")
SHARED = os.path.normpath(os.path.join(REPO, "..", "shared", "data"))
BOOKSHELF = os.path.join(REPO, "examples", "bookshelf")

CLASSES = ["panic", "hang", "data_loss", "wrong_exit0", "bad_message", "clean_error", "ok"]
BAD = CLASSES[:5]
STOP_WITHIN = 5.0  # seconds a Ctrl-C'd run may take to stop
MEM_LIMIT = 16 << 30  # address space of every run: an absurd allocation aborts, it does not swap
MAX_STDERR = 2000

K = None  # the kinergy binary
PY = None  # the Python interpreter with `kinergy`, or None
SCR = None  # scratch root
FIX = None  # fixtures
QUICK = False

# ----------------------------------------------------------------------------- utilities


def w(path, data):
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    with open(path, "wb" if isinstance(data, (bytes, bytearray)) else "w") as f:
        f.write(data)


def rb(path):
    with open(path, "rb") as f:
        return f.read()


def sha(data):
    return hashlib.sha256(data).hexdigest()[:16]


def q(args):
    return " ".join(shlex.quote(str(a)) for a in args)


def snap(path, depth=0):
    """A hashable description of a path (not following links): bytes, link target, tree."""
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return ("missing",)
    except OSError as e:
        return ("error", e.errno)
    if stat.S_ISLNK(st.st_mode):
        return ("link", os.readlink(path))
    if stat.S_ISDIR(st.st_mode):
        try:
            names = sorted(os.listdir(path))
        except OSError as e:
            return ("dir-error", e.errno)
        return ("dir", tuple((n, snap(os.path.join(path, n), depth + 1)) for n in names))
    if stat.S_ISREG(st.st_mode):
        try:
            return ("file", sha(rb(path)))
        except OSError as e:
            return ("file-error", e.errno)
    return ("other", stat.S_IFMT(st.st_mode), getattr(st, "st_rdev", 0))


def file_stats(root):
    """{relative path: (inode, mtime_ns, size)} of the regular files under root."""
    out = {}
    for base, _d, fn in os.walk(root):
        for f in fn:
            p = os.path.join(base, f)
            try:
                st = os.lstat(p)
            except OSError:
                continue
            if stat.S_ISREG(st.st_mode):
                out[os.path.relpath(p, root)] = (st.st_ino, st.st_mtime_ns, st.st_size)
    return out


INTERNAL = re.compile(r"\b[A-Z][A-Za-z]+ \{ [a-z_]+: |\bSome\(|max_evaluations|particle_swarm|"
                      r"\brest_speed\b|baseline\.|os error 17\)")
LONG_NUM = re.compile(r"\d{31,}")
NONFINITE = re.compile(r"(?<![A-Za-z0-9_])[-+]?(?:inf(?:inity)?|nan)(?![A-Za-z0-9_])", re.I)
BACKTICK = re.compile(r"`[^`\n]*`")


def long_number(text):
    m = LONG_NUM.search(BACKTICK.sub("``", text))
    if m:
        return "a %d-digit number (%r...)" % (len(m.group(0)), m.group(0)[:12])
    return None


def nonfinite(text):
    m = NONFINITE.search(BACKTICK.sub("``", text))
    if m:
        s = max(0, m.start() - 30)
        return "%r in %r" % (m.group(0), text[s:m.end() + 30])
    return None


def limit_memory():
    os.setsid()
    try:
        resource.setrlimit(resource.RLIMIT_AS, (MEM_LIMIT, MEM_LIMIT))
    except (ValueError, OSError):
        pass
    try:
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    except (ValueError, OSError):
        pass


def group_alive(pgid):
    try:
        os.killpg(pgid, 0)
        return True
    except ProcessLookupError:
        return False
    except PermissionError:
        return True


# ----------------------------------------------------------------------------- running


class Step:
    def __init__(self, kind, argv, cwd, env_note=""):
        self.kind = kind  # "kin" | "py"
        self.argv = argv
        self.cwd = cwd
        self.env_note = env_note
        self.rc = None
        self.wall = 0.0
        self.out = b""
        self.err = b""
        self.timed_out = False
        self.sent = None  # the signal we sent, if any
        self.stop = None  # seconds from the signal to the exit
        self.result = None  # a Python step's @@R record
        self.label = ""

    @property
    def text_err(self):
        return self.err.decode("utf-8", "replace")

    @property
    def text_out(self):
        return self.out.decode("utf-8", "replace")

    def command(self):
        exe = K if self.kind == "kin" else PY
        return "cd %s && %s%s %s" % (shlex.quote(self.cwd), self.env_note, shlex.quote(exe), q(self.argv))


def run_proc(step, exe, env=None, timeout=60, sig=None, stdin=None):
    """Runs exe+argv; sig = (signal, delay): send it to the process group after delay s."""
    full_env = dict(os.environ)
    full_env.pop("SLURM_ARRAY_TASK_ID", None)
    full_env.pop("SLURM_ARRAY_TASK_MIN", None)
    full_env.pop("SLURM_ARRAY_TASK_COUNT", None)
    full_env["RUST_BACKTRACE"] = "0"
    envb = None
    if env:
        if any(isinstance(v, bytes) for v in env.values()):
            envb = {k.encode(): v.encode() for k, v in full_env.items()}
            for k, v in env.items():
                envb[k.encode()] = v if isinstance(v, bytes) else v.encode()
        else:
            full_env.update(env)
    t0 = time.monotonic()
    p = subprocess.Popen([exe] + [str(a) for a in step.argv], cwd=step.cwd,
                         stdin=subprocess.DEVNULL if stdin is None else subprocess.PIPE,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         env=envb if envb is not None else full_env, preexec_fn=limit_memory)
    pgid = p.pid
    deadline = timeout
    if sig:
        signum, delay = sig
        try:
            out, err = p.communicate(input=stdin, timeout=delay)
            step.out, step.err = out, err
            step.rc = p.returncode
            step.wall = time.monotonic() - t0
            step.label = "finished before the signal"
            return step
        except subprocess.TimeoutExpired:
            pass
        ts = time.monotonic()
        try:
            os.killpg(pgid, signum)
        except ProcessLookupError:
            pass
        step.sent = signum
        if signum == signal.SIGKILL:
            deadline = 10
        else:
            deadline = STOP_WITHIN
        try:
            step.out, step.err = p.communicate(timeout=deadline)
            step.stop = time.monotonic() - ts
            # every process of the group must stop too (forked workers)
            while group_alive(pgid) and time.monotonic() - ts < deadline:
                time.sleep(0.05)
            if group_alive(pgid):
                step.timed_out = True
                step.label = "a process of the group still ran %.0f s after the signal" % deadline
                os.killpg(pgid, signal.SIGKILL)
        except subprocess.TimeoutExpired:
            step.timed_out = True
            try:
                os.killpg(pgid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            step.out, step.err = p.communicate()
        step.rc = p.returncode
        step.wall = time.monotonic() - t0
        return step
    try:
        step.out, step.err = p.communicate(input=stdin, timeout=deadline)
    except subprocess.TimeoutExpired:
        step.timed_out = True
        try:
            os.killpg(pgid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        step.out, step.err = p.communicate()
    if group_alive(pgid):
        try:
            os.killpg(pgid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    step.rc = p.returncode
    step.wall = time.monotonic() - t0
    return step


PRELUDE = r'''
import json, sys, os, warnings, math, pathlib
warnings.simplefilter("always")
import numpy as np
import kinergy as k
_W = []
def _sw(message, category, filename, lineno, file=None, line=None):
    _W.append("%s: %s" % (category.__name__, message))
warnings.showwarning = _sw
def _done(**kw):
    kw["warnings"] = _W
    sys.stdout.write("\n@@R " + json.dumps(kw, default=str) + "\n")
    sys.stdout.flush()
def _run(f):
    try:
        r = f()
    except KeyboardInterrupt as e:
        _done(ok=False, exc="KeyboardInterrupt", mro=["KeyboardInterrupt"], msg=str(e),
              notes=[str(n) for n in getattr(e, "__notes__", [])],
              cause=repr(e.__cause__ or e.__context__) if (e.__cause__ or e.__context__) else "")
        sys.exit(130)
    except BaseException as e:
        _done(ok=False, exc=type(e).__name__, mro=[c.__name__ for c in type(e).__mro__],
              msg=str(e)[:4000], notes=[str(n) for n in getattr(e, "__notes__", [])])
        sys.exit(3)
    _done(ok=True, value=r)
'''


def py_script(body):
    return PRELUDE + "\n" + body + "\n"


# ----------------------------------------------------------------------------- a case


class Case:
    def __init__(self, family, label, fn, **kw):
        self.family = family
        self.label = label
        self.fn = fn  # fn(ctx) -> None
        self.needs_py = kw.get("needs_py", False)


class Ctx:
    def __init__(self, case, cdir):
        self.case = case
        self.dir = cdir
        self.steps = []
        self.findings = []
        self.clean = False  # an expected refusal was seen
        self.echo = []  # the case's own long names, stripped before the number checks

    # -- findings
    def find(self, cls, detail, step=None):
        if step is not None and step in self.steps:
            detail = "step %d: %s" % (self.steps.index(step) + 1, detail)
        self.findings.append((cls, detail))

    def worst(self):
        for c in BAD:
            if any(f[0] == c for f in self.findings):
                return c
        return "clean_error" if self.clean else "ok"

    # -- running
    def kin(self, args, cwd=None, env=None, timeout=90, sig=None, stdin=None, note=""):
        env_note = "".join("%s=%s " % (k, shlex.quote(v if isinstance(v, str) else repr(v)))
                           for k, v in (env or {}).items())
        st = Step("kin", [str(a) for a in args], cwd or self.dir, env_note)
        st.label = note
        run_proc(st, K, env=env, timeout=timeout, sig=sig, stdin=stdin)
        self.steps.append(st)
        self.auto(st)
        return st

    def py(self, body, cwd=None, timeout=90, sig=None, name="case.py"):
        path = os.path.join(self.dir, name)
        w(path, py_script(body))
        st = Step("py", [path], cwd or self.dir)
        run_proc(st, PY, timeout=timeout, sig=sig)
        self.steps.append(st)
        for line in st.text_out.splitlines():
            if line.startswith("@@R "):
                try:
                    st.result = json.loads(line[4:])
                except ValueError:
                    pass
        self.auto(st)
        return st

    def auto(self, st):
        """Checks every step gets: hangs, crashes, stderr size, internal names, long numbers."""
        err = st.text_err
        if st.timed_out:
            if st.sent:
                self.find("hang", "did not stop within %gs of signal %d%s" % (
                    STOP_WITHIN if st.sent != signal.SIGKILL else 10, st.sent,
                    " (%s)" % st.label if st.label else ""), st)
            else:
                self.find("hang", "no exit within the timeout (%.0f s)" % st.wall, st)
        if st.rc == 101 or "panicked" in err or "PanicException" in err or (
                st.result and st.result.get("exc") == "PanicException"):
            self.find("panic", "panic: %s" % err.strip()[-300:], st)
        elif st.rc is not None and st.rc < 0 and not st.sent and not st.timed_out:
            self.find("panic", "killed by signal %d (crash or memory blow-up)" % -st.rc, st)
        elif st.rc is not None and st.rc < 0 and st.sent and -st.rc != st.sent and not st.timed_out:
            self.find("panic", "killed by signal %d after we sent %d" % (-st.rc, st.sent), st)
        if st.kind == "kin":
            if len(st.err) > MAX_STDERR:
                self.find("bad_message", "stderr is %d bytes" % len(st.err), st)
            if st.rc in (1, 2) and not err.strip():
                self.find("bad_message", "exit %d with nothing on stderr" % st.rc, st)
            m = INTERNAL.search(err)
            if m:
                s = max(0, m.start() - 60)
                self.find("bad_message", "internal name in the message: %r" % err[s:m.end() + 60], st)
        else:
            r = st.result or {}
            msg = r.get("msg") or ""
            m = INTERNAL.search(msg)
            if m:
                s = max(0, m.start() - 60)
                self.find("bad_message", "internal name in the exception: %r" % msg[s:m.end() + 60], st)
            if len(msg) > MAX_STDERR:
                self.find("bad_message", "exception message is %d bytes" % len(msg), st)
            if st.result is None and not st.timed_out and not st.sent and st.rc not in (None,) and st.rc >= 0:
                self.find("panic" if st.rc != 0 else "bad_message",
                          "the Python process ended without a result (exit %s): %s" % (st.rc, err.strip()[-300:]), st)
        for where, text in (("stdout", st.text_out), ("stderr", err)):
            for e in self.echo:
                text = text.replace(e, "")
            ln = long_number(text)
            if ln:
                self.find("wrong_exit0" if st.rc == 0 else "bad_message", "%s prints %s" % (where, ln), st)
                break

    # -- expectations
    def refused(self, st, hints=(), codes=(2,), what="a refusal"):
        """The step must refuse: a non-zero exit in codes with a message naming a hint."""
        if st.timed_out or st.rc is None or st.rc < 0 or st.rc == 101:
            return False
        if st.kind == "py":
            r = st.result or {}
            if r.get("ok"):
                self.find("wrong_exit0", "returned where %s was expected" % what, st)
                return False
            msg = (r.get("msg") or "") + " " + " ".join(r.get("notes") or [])
            if not msg.strip():
                self.find("bad_message", "%s with an empty message" % r.get("exc"), st)
                return False
            if hints and not any(h.lower() in msg.lower() for h in hints):
                self.find("bad_message", "%s: %r names none of %r" % (r.get("exc"), msg[:200], list(hints)[:5]), st)
                return False
            self.clean = True
            return True
        if st.rc == 0:
            self.find("wrong_exit0", "exit 0 where %s was expected" % what, st)
            return False
        err = st.text_err
        if st.rc not in codes:
            self.find("bad_message", "exit %d where %s (exit %s) was expected: %s" % (
                st.rc, what, "/".join(map(str, codes)), err.strip()[:200]), st)
            return False
        if hints and err.strip() and not any(h.lower() in err.lower() for h in hints):
            self.find("bad_message", "message names none of %r: %s" % (list(hints)[:5], err.strip()[:200]), st)
            return False
        self.clean = True
        return True

    def succeeded(self, st, what="a normal run"):
        """The step must succeed (exit 0 / a Python return)."""
        if st.timed_out or st.rc is None or (st.rc < 0) or st.rc == 101:
            return False
        if st.kind == "py":
            r = st.result or {}
            if r.get("ok"):
                return True
            self.find("bad_message", "%s raised for %s: %s" % (r.get("exc"), what, (r.get("msg") or "")[:200]), st)
            return False
        if st.rc == 0:
            return True
        self.find("bad_message", "exit %d for %s (refused a valid input): %s" % (
            st.rc, what, st.text_err.strip()[:200]), st)
        return False


# ----------------------------------------------------------------------------- fixtures

CLIPS = []  # "pNN/rMM.bvh"
EXTRA = {}  # name -> path of a take from ../shared/data (if present)


def ds(rel):
    return os.path.join(FIX, "ds", rel)


def kin_fixture(args, cwd=None, timeout=300):
    r = subprocess.run([K] + args, cwd=cwd or FIX, stdin=subprocess.DEVNULL, capture_output=True,
                       timeout=timeout)
    if r.returncode != 0:
        raise SystemExit("fixture command failed: kinergy %s\n%s" % (q(args), r.stderr.decode(errors="replace")))
    return r


def prepare_fixtures():
    os.makedirs(FIX)
    shutil.copytree(DATA, os.path.join(FIX, "ds"))
    for r in csv.DictReader(open(os.path.join(FIX, "ds", "manifest.csv"), newline="")):
        CLIPS.append(r["clip"])
    for name, rel in (("26_10", "cmu-lift/26_10.bvh"), ("26_11", "cmu-lift/26_11.bvh"),
                      ("74_07", "cmu-lift/74_07.bvh"), ("active_001", "bandai-raise-left/active_001.bvh"),
                      ("active_002", "bandai-raise-left/active_002.bvh"),
                      ("elderly_001", "bandai-raise-left/elderly_001.bvh")):
        src = os.path.join(SHARED, rel)
        if os.path.exists(src):
            dst = os.path.join(FIX, "extra", os.path.basename(rel))
            os.makedirs(os.path.dirname(dst), exist_ok=True)
            shutil.copy(src, dst)
            EXTRA[name] = dst
    kin_fixture(["fit", ds("p01/r01.bvh"), "--model", "sa", "--budget", "30", "-q", "-o",
                 os.path.join(FIX, "p_sa.json")])
    kin_fixture(["fit", ds("p01/r09.bvh"), "--model", "sc", "--budget", "30", "-q", "-o",
                 os.path.join(FIX, "p_sc.json")])
    # a collected library of 2 persons x 3 takes, model sc (compare --library's tables)
    lib = os.path.join(FIX, "lib6")
    for c in ("p01/r01.bvh", "p01/r02.bvh", "p01/r03.bvh", "p02/r01.bvh", "p02/r02.bvh", "p02/r03.bvh"):
        os.makedirs(os.path.join(lib, os.path.dirname(c)), exist_ok=True)
        shutil.copy(ds(c), os.path.join(lib, c))
    kin_fixture(["fit", lib, "--per", "clip", "--model", "sc", "--budget", "24", "--threads", "1", "-q",
                 "--out-dir", os.path.join(FIX, "lib6.fits")])
    # a small collected library of 3 takes, model sa (record-name and bounds cases)
    lib = os.path.join(FIX, "lib3")
    for c in ("p01/r01.bvh", "p01/r02.bvh", "p02/r01.bvh"):
        os.makedirs(os.path.join(lib, os.path.dirname(c)), exist_ok=True)
        shutil.copy(ds(c), os.path.join(lib, c))
    kin_fixture(["fit", lib, "--per", "clip", "--model", "sa", "--budget", "20", "--threads", "1", "-q",
                 "--out-dir", os.path.join(FIX, "lib3.fits")])


def make_lib(root, rng, n_takes, persons=None, names=None):
    """A library of copies of synthetic takes: {relative path: source}."""
    persons = persons or rng.sample(["p01", "p02", "p03", "p04"], rng.randint(1, 3))
    chosen = {}
    pool = [c for c in CLIPS if c.split("/")[0] in persons]
    for c in rng.sample(pool, min(n_takes, len(pool))):
        chosen[c] = ds(c)
    for rel, src in chosen.items():
        os.makedirs(os.path.join(root, os.path.dirname(rel)), exist_ok=True)
        shutil.copy(src, os.path.join(root, rel))
    return chosen


def lib_args(model="sa", budget=30, extra=()):
    return ["--per", "clip", "--model", model, "--budget", str(budget), "--threads", "1", "-q"] + list(extra)


# ----------------------------------------------------------------------------- library checks


def result_fp(doc):
    """What a result file says, independent of how its take's path was spelled."""
    fit = doc.get("fit", {})
    reaches = tuple((tuple(r.get("frames", [])), (r.get("arm") or {}).get("side"),
                     repr(r.get("distance_m"))) for r in fit.get("reaches", []))
    return (doc.get("model"), json.dumps(doc.get("values"), sort_keys=True), repr(fit.get("score_m")),
            reaches, json.dumps(fit.get("nested"), sort_keys=True))


def read_library(D, base=None):
    """({(clip, arm, onset, end): fingerprint}, problems) from D/library.csv and its results."""
    rows, problems = {}, []
    path = os.path.join(D, "library.csv")
    if not os.path.isfile(path):
        return None, ["no library.csv"]
    try:
        table = list(csv.DictReader(open(path, newline="", encoding="utf-8")))
    except Exception as e:
        return None, ["library.csv does not parse: %r" % e]
    seen_results = {}
    for r in table:
        key = (r.get("clip"), r.get("arm"), r.get("onset"), r.get("end"))
        if key in rows:
            problems.append("reach %s listed twice in library.csv" % (key,))
        res = r.get("result") or ""
        if res in seen_results:
            problems.append("reaches %s and %s share the result file %s" % (seen_results[res], key, res))
        seen_results[res] = key
        rp = os.path.join(D, res)
        try:
            doc = json.load(open(rp))
        except Exception as e:
            problems.append("result %s of %s does not read: %r" % (res, key, e))
            rows[key] = None
            continue
        reaches = doc.get("fit", {}).get("reaches", [])
        if not reaches:
            problems.append("result %s has no reach" % res)
        else:
            r0 = reaches[0]
            clip = r0.get("clip", "")
            real = os.path.basename(os.path.realpath(os.path.join(base, clip))) if base else ""
            if os.path.basename(key[0] or "") not in (os.path.basename(clip), real):
                problems.append("result %s is of clip %s, its row says %s" % (res, clip, key[0]))
            if list(r0.get("frames", [])) != [int(key[2] or -1), int(key[3] or -1)]:
                problems.append("result %s has frames %s, its row %s..%s" % (res, r0.get("frames"), key[2], key[3]))
            side = (r0.get("arm") or {}).get("side")
            if side != key[1]:
                problems.append("result %s is of arm %s, its row says %s" % (res, side, key[1]))
            d = r.get("distance_%s_m" % doc.get("model"))
            if d and r0.get("distance_m") is not None and doc.get("fit", {}).get("score_m") is not None:
                try:
                    if abs(float(d) - float(doc["fit"]["score_m"])) > 1e-12 * max(1.0, abs(float(d))):
                        problems.append("row %s says %s m, its result %s m" % (key, d, doc["fit"]["score_m"]))
                except (TypeError, ValueError):
                    problems.append("row %s distance %r" % (key, d))
        rows[key] = result_fp(doc)
    return rows, problems


REF_CACHE = {}


def lib_signature(LIB):
    items = []
    for base, dnames, fn in os.walk(LIB):
        dnames.sort()
        for f in sorted(fn):
            p = os.path.join(base, f)
            if os.path.isfile(p) and not os.path.islink(p):
                items.append((os.path.relpath(p, LIB), sha(rb(p))))
    return tuple(items)


def reference(LIB, args):
    """A one-machine run of the takes under LIB with args: read_library's rows (cached)."""
    key = (lib_signature(LIB), tuple(args))
    if key in REF_CACHE:
        return REF_CACHE[key]
    n = len(REF_CACHE)
    ref_root = os.path.join(SCR, "ref", "%05d" % n)
    shutil.copytree(LIB, os.path.join(ref_root, "LIB"), symlinks=True)
    out = os.path.join(ref_root, "D")
    r = subprocess.run([K, "fit", "LIB"] + list(args) + ["--out-dir", out], cwd=ref_root,
                       stdin=subprocess.DEVNULL, capture_output=True, timeout=600, preexec_fn=limit_memory)
    if r.returncode not in (0, 1):
        REF_CACHE[key] = (None, "the reference run failed (exit %d): %s" % (r.returncode, r.stderr[:300]))
    else:
        rows, problems = read_library(out)
        REF_CACHE[key] = (rows, "; ".join(problems) if problems else None)
    shutil.rmtree(os.path.join(ref_root, "LIB"), ignore_errors=True)
    return REF_CACHE[key]


def verify_library(ctx, D, LIB, args, st=None, what="collect"):
    """After an exit 0 of `what`: every take has exactly its one-machine result."""
    rows, problems = read_library(D, base=ctx.dir)
    if rows is None:
        ctx.find("wrong_exit0", "%s exited 0 but %s" % (what, "; ".join(problems)), st)
        return False
    for p in problems[:3]:
        ctx.find("data_loss", "%s exited 0 but %s" % (what, p), st)
    ref, why = reference(LIB, args)
    if ref is None:
        ctx.find("bad_message", "reference: %s" % why, st)
        return False
    missing = [k for k in ref if k not in rows]
    extra = [k for k in rows if k not in ref]
    differ = [k for k in ref if k in rows and rows[k] != ref[k]]
    if missing:
        ctx.find("data_loss", "%s 'complete' but %d reach(es) have no row/result, e.g. %s" % (
            what, len(missing), missing[0]), st)
    if extra:
        ctx.find("data_loss", "%s lists %d reach(es) the takes do not have, e.g. %s" % (what, len(extra), extra[0]), st)
    if differ:
        ctx.find("data_loss", "%s: %d result(s) differ from the one-machine run, e.g. %s" % (
            what, len(differ), differ[0]), st)
    return not (problems or missing or extra or differ)


# ----------------------------------------------------------------------------- family 00


def make_target(c, kind, name):
    """Makes the output target `name` of `kind` in case folder c; returns its path."""
    p = os.path.join(c, name)
    if kind == "fifo":
        os.mkfifo(p)
    elif kind == "chr-null":
        os.mknod(p, stat.S_IFCHR | 0o666, os.makedev(1, 3))
    elif kind == "chr-full":
        os.mknod(p, stat.S_IFCHR | 0o666, os.makedev(1, 7))
    elif kind == "folder":
        os.makedirs(p)
    elif kind == "folder-nonempty":
        os.makedirs(p)
        w(os.path.join(p, "keep.txt"), "keep\n")
    elif kind == "socket":
        s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        s.bind(p)
        s.close()
    elif kind.startswith("link-"):
        inner = make_target(c, kind[5:], "inner-" + name)
        os.symlink(os.path.basename(inner), p)
    elif kind == "dangling":
        os.symlink("nowhere-" + name, p)
    elif kind == "regular":
        w(p, "old contents\n")
    return p


SPECIAL = ["fifo", "chr-null", "chr-full", "folder", "folder-nonempty", "socket", "link-fifo",
           "link-chr-null", "link-folder"]


def fam_outputs(rng, n):
    fam = "00_outputs"
    cases = []
    kinds = SPECIAL + ["dangling", "regular", "absent"]
    writers = ["py-write_bvh", "py-Params.save", "py-fit-save", "cli-convert", "cli-fit", "cli-synthesize",
               "cli-segment-manifest"]
    combos = [(k, wr) for k in kinds for wr in writers]
    rng.shuffle(combos)
    combos = combos[:n] if n < len(combos) else combos
    for kind, writer in combos:
        stem = rng.choice(["out", "o ut", "ünï", "-x", "a@b"])
        ext = {"py-Params.save": ".json", "py-fit-save": ".json", "cli-fit": ".json",
               "cli-segment-manifest": ".csv"}.get(writer, ".bvh")
        name = stem + ext

        def fn(ctx, kind=kind, writer=writer, name=name):
            c = ctx.dir
            os.makedirs(c, exist_ok=True)
            target = os.path.join(c, name) if kind == "absent" else make_target(c, kind, name)
            watch = [target] + ([os.path.join(c, "inner-" + name)] if kind.startswith("link-") else [])
            before = {p: snap(p) for p in watch}
            clip = ds("p01/r09.bvh")
            P = os.path.join(FIX, "p_sa.json")
            if writer.startswith("py-"):
                if PY is None:
                    return
                body = {
                    "py-write_bvh": "c = k.read_bvh(%r)\n_run(lambda: c.write_bvh(%r))" % (clip, name),
                    "py-Params.save": "p = k.Params.load(%r)\n_run(lambda: p.save(%r))" % (P, name),
                    "py-fit-save": "_run(lambda: k.fit(%r, model='sa', budget=20, threads=1).save(%r))" % (clip, name),
                }[writer]
                st = ctx.py(body, timeout=30)
            else:
                name = "./" + name if name.startswith("-") else name
                args = {
                    "cli-convert": ["convert", clip, "-o", name],
                    "cli-fit": ["fit", clip, "--model", "sa", "--budget", "20", "--threads", "1", "-q", "-o", name],
                    "cli-synthesize": ["synthesize", clip, "--params", P, "-q", "-o", name],
                    "cli-segment-manifest": ["segment", clip, "-q", "--manifest", name],
                }[writer]
                st = ctx.kin(args, timeout=30)
            for p, b in before.items():
                if kind in SPECIAL and snap(p) != b:
                    ctx.find("data_loss", "%s (a %s) was replaced or changed: %s -> %s" % (
                        os.path.basename(p), kind, str(b)[:50], str(snap(p))[:50]), st)
            if kind in SPECIAL:
                ctx.refused(st, hints=[name, os.path.basename(name), "not a regular file", "folder", "FIFO",
                                       "device", "socket"], codes=(2,), what="a refusal of a %s" % kind)
            elif kind in ("regular", "absent"):
                if ctx.succeeded(st):
                    if not os.path.isfile(target) or os.path.islink(target):
                        ctx.find("wrong_exit0", "exit 0 but %s is not a regular file" % name, st)
                    elif rb(target) == b"old contents\n":
                        ctx.find("wrong_exit0", "exit 0 but %s was not written" % name, st)
            else:  # dangling link: a refusal or a write, never a hang or a crash
                if st.rc == 0 or (st.result or {}).get("ok"):
                    pass
                else:
                    ctx.refused(st, hints=[name], codes=(1, 2), what="a refusal of a dangling link")
        cases.append(Case(fam, "%s -> %s (%r)" % (writer, kind, name), fn, needs_py=writer.startswith("py-")))
    return cases


# ----------------------------------------------------------------------------- family 01

NAME_POOL = [
    "26_10.bvh", "26_10_4-66.bvh", "26_10_7-70.bvh", "26_10.bvh@4-66.bvh", "26_10.bvh@7-70.bvh",
    "26_10.bvh@4-66@left.bvh", "a@b.bvh", "a@@b.bvh", "a@.bvh", "@.bvh", "@@.bvh", "a@1-2.bvh", "a.bvh",
    "a_1-2.bvh", "a.bvh.bvh", "x/a.bvh", "x_a.bvh", "x@/a.bvh", "x/a@b.bvh", "x@@/a.bvh", "%41.bvh", "A.bvh",
    "a b.bvh", "ü.bvh", "-x.bvh", "a.BVH", "r.bvh", "r.bvh.json/a.bvh", "r.bvh@1-2.json/a.bvh",
    "shards/a.bvh", "shards/1-of-1.bvh", "library.csv.bvh", "p01/r01.bvh", "p01_r01.bvh", "p01/r01_7-71.bvh",
    "p01@r01.bvh", "deep/er/r01.bvh", "deep/er@/r01.bvh", "L" * 240 + ".bvh", "L" * 251 + ".bvh",
    "library.csv/a.bvh", "skipped.csv/a.bvh",
]


def fam_names(rng, n):
    fam = "01_names"
    cases = []
    srcs = [ds(c) for c in CLIPS[:20]] + list(EXTRA.values())
    for i in range(n):
        k = rng.randint(3, 7)
        names = rng.sample(NAME_POOL, k)
        if rng.random() < 0.35 and "r.bvh" not in names:
            names += ["r.bvh", rng.choice(["r.bvh.json/a.bvh", "r.bvh@1-2.json/a.bvh", "r.bvh@@x.json/b.bvh"])]
        if rng.random() < 0.3 and "26_10.bvh" not in names:
            names.append("26_10.bvh")
        names = list(dict.fromkeys(names))
        entries = []
        for nm in names:
            if nm.startswith("26_10") and "26_10" in EXTRA and rng.random() < 0.7:
                src = EXTRA["26_10"]
            else:
                src = rng.choice(srcs)
            entries.append((nm, src))
        mode = rng.choice(["auto", "auto", "auto", "select-all", "segments"])
        top = rng.choice(["", "", "sub/"])

        def fn(ctx, entries=entries, mode=mode, top=top):
            c = ctx.dir
            LIB = os.path.join(c, "LIB")
            for nm, src in entries:
                p = os.path.join(LIB, top + nm)
                os.makedirs(os.path.dirname(p), exist_ok=True)
                shutil.copy(src, p)
            lib_before = snap(LIB)
            args = lib_args("sa", 20)
            if mode == "auto":
                args += ["--arm", "auto"]
            elif mode == "select-all":
                args += ["--select", "all"]
            else:
                rows = []
                for nm, src in entries:
                    rel = os.path.join("LIB", top + nm)
                    frames = None
                    with open(os.path.join(c, rel), "rb") as f:
                        for line in f:
                            if line.startswith(b"Frames:"):
                                frames = int(line.split()[1])
                                break
                    e = min(frames or 60, 60)
                    rows.append([rel, 5, e, "right", "reach", "p"])
                    if len(rows) % 2:
                        rows.append([rel, 5, e, "left", "reach", "p"])  # same frames: @arm
                        rows.append([rel, 2, e - 1, "right", "reach", "p"])
                buf = io.StringIO()
                wr = csv.writer(buf, lineterminator="\n")
                wr.writerow(["clip", "onset", "end", "arm", "label", "person"])
                for r in rows:
                    wr.writerow(r)
                w(os.path.join(c, "seg.csv"), buf.getvalue())
                args += ["--segments", "seg.csv"]
            st = ctx.kin(["fit", "LIB"] + args + ["--out-dir", "D"], timeout=180)
            if snap(LIB) != lib_before:
                ctx.find("data_loss", "the takes under LIB changed", st)
            if st.rc != 0:
                longest = max(len(os.path.basename(nm)) for nm, _ in entries)
                if st.rc == 2 and longest + 5 > 255:
                    ctx.refused(st, hints=["L" * 20, "long"], what="a refusal of a too long name")
                    return
                ctx.succeeded(st, what="takes whose names only look alike")
                return
            rows, problems = read_library(os.path.join(c, "D"), base=c)
            if rows is None:
                ctx.find("wrong_exit0", "exit 0 but %s" % "; ".join(problems), st)
                return
            for p in problems[:3]:
                ctx.find("data_loss", p, st)
            # every take has a row or a skipped row
            listed = set(k[0] for k in rows)
            skipped = set()
            sp = os.path.join(c, "D", "skipped.csv")
            if os.path.exists(sp):
                skipped = set(r.get("clip") for r in csv.DictReader(open(sp, newline="", encoding="utf-8")))
            for nm, _src in entries:
                rel = (top + nm)
                if nm.endswith(".BVH"):
                    continue
                if not any(x == rel or (x or "").endswith("/" + rel) or rel.endswith("/" + (x or "~"))
                           for x in listed | skipped):
                    if mode != "segments":
                        ctx.find("data_loss", "take %s has neither a row in library.csv nor in skipped.csv" % rel, st)
            files = [x for x in file_stats(os.path.join(c, "D")) if x.endswith(".json") and not x.startswith("shards/")]
            if len(files) < len(rows):
                ctx.find("data_loss", "%d reaches but %d result files" % (len(rows), len(files)), st)
            st2 = ctx.kin(["collect", "D"])
            if ctx.succeeded(st2, what="collect of a whole library"):
                if mode != "segments":
                    verify_library(ctx, os.path.join(c, "D"), LIB, args, st2)
        cases.append(Case(fam, "%s%s: %s" % (mode, " under sub/" if top else "", ", ".join(
            (nm if len(nm) < 40 else "L*%d.bvh" % (len(nm) - 4)) + ("[26_10]" if src == EXTRA.get("26_10") else "")
            for nm, src in entries)), fn))
    return cases


# ----------------------------------------------------------------------------- family 02

TAKE_EDITS = ["delete-take", "add-take", "add-person", "grow-take", "grow-bytes", "shrink-take", "edit-take",
              "replace-take", "rename-take", "swap-takes"]
RESULT_EDITS = ["delete-result", "truncate-result", "copy-over-result", "other-model-result",
                "edit-result-value", "empty-result", "result-to-folder", "result-symlink"]
RECORD_EDITS = ["stray:2-of-1.csv", "stray:0-of-1.csv", "stray:01-of-1.csv", "stray:1-of-99999999999.csv",
                "stray:1-of-1000000.csv", "stray:1-of-100001.csv", "stray:3-of-2.csv", "stray:2-of-1.json",
                "empty-record", "header-only-record", "bom-record", "extra-column-record", "crlf-record",
                "dup-reach-row", "drop-take-row", "drop-reach-row", "header-seed-edited", "delete-header-json",
                "delete-takes-json", "takes-json-size-edited", "foreign-record"]
BENIGN_EDITS = ["none", "touch-take", "touch-result", "same-bytes-new-inode", "touch-record"]


def bvh_frames_edit(path, how, rng):
    data = rb(path).decode("latin-1")
    head, motion = data.split("MOTION", 1)
    lines = motion.split("\n")
    fi = next(i for i, l in enumerate(lines) if l.startswith("Frames:"))
    n = int(lines[fi].split()[1])
    first = next(i for i, l in enumerate(lines) if l.startswith("Frame Time:")) + 1
    frames = [l for l in lines[first:] if l.strip()]
    if how == "grow":
        frames.append(frames[-1])
        lines[fi] = "Frames: %d" % (n + 1)
    elif how == "shrink":
        frames.pop()
        lines[fi] = "Frames: %d" % (n - 1)
    elif how == "edit":
        k = len(frames) // 2
        vals = frames[k].split()
        j = rng.randrange(len(vals))
        v = vals[j]
        vals[j] = v[:-1] + ("1" if v[-1] != "1" else "2") if v[-1].isdigit() else v + "1"
        frames[k] = " ".join(vals)
    out = head + "MOTION" + "\n".join(lines[:first]) + "\n" + "\n".join(frames) + "\n"
    w(path, out.encode("latin-1"))


def library_results(D):
    out = []
    for rel in file_stats(D):
        if rel.endswith(".json") and not rel.startswith("shards/") and not rel.startswith("shards" + os.sep):
            out.append(rel)
    return sorted(out)


def apply_edit(ctx, edit, rng, LIB, D, N, takes, base):
    """Applies edit; returns (hints for a message, files to remove before a recovery, is_benign)."""
    shards = os.path.join(D, "shards")
    results = library_results(D)
    recs = sorted(x for x in os.listdir(shards) if x.endswith(".csv")) if os.path.isdir(shards) else []
    heads = sorted(x for x in os.listdir(shards) if re.match(r"^\d+-of-\d+\.json$", x)) if os.path.isdir(shards) else []
    if edit in BENIGN_EDITS:
        if edit == "touch-take":
            t = rng.choice(sorted(takes))
            os.utime(os.path.join(LIB, t), (time.time() + 100, time.time() + 100))
        elif edit == "touch-result" and results:
            os.utime(os.path.join(D, rng.choice(results)), (time.time() + 100, time.time() + 100))
        elif edit == "same-bytes-new-inode":
            t = os.path.join(LIB, rng.choice(sorted(takes)))
            data = rb(t)
            os.unlink(t)
            w(t, data)
        elif edit == "touch-record" and recs:
            os.utime(os.path.join(shards, rng.choice(recs)), (time.time() + 100, time.time() + 100))
        return [], [], True
    if edit in TAKE_EDITS:
        t = rng.choice(sorted(takes))
        tp = os.path.join(LIB, t)
        if edit == "delete-take":
            os.unlink(tp)
            takes.discard(t)
            return [t, os.path.basename(t)], [], False
        if edit in ("add-take", "add-person"):
            new = [c for c in CLIPS if c not in takes]
            src = rng.choice(new)
            if edit == "add-take":
                rel = os.path.join(os.path.dirname(t), "n" + os.path.basename(src))
            else:
                rel = os.path.join("p09", os.path.basename(src))
            os.makedirs(os.path.dirname(os.path.join(LIB, rel)), exist_ok=True)
            shutil.copy(ds(src), os.path.join(LIB, rel))
            takes.add(rel)
            return [rel, os.path.basename(rel)], [], False
        if edit == "grow-take":
            bvh_frames_edit(tp, "grow", rng)
        elif edit == "shrink-take":
            bvh_frames_edit(tp, "shrink", rng)
        elif edit == "edit-take":
            bvh_frames_edit(tp, "edit", rng)
        elif edit == "grow-bytes":
            with open(tp, "ab") as f:
                f.write(b"\n")
        elif edit == "replace-take":
            other = rng.choice([x for x in sorted(takes) if x != t] or [t])
            shutil.copy(os.path.join(LIB, other), tp) if other != t else bvh_frames_edit(tp, "edit", rng)
        elif edit == "rename-take":
            rel = os.path.join(os.path.dirname(t), "z" + os.path.basename(t))
            os.rename(tp, os.path.join(LIB, rel))
            takes.discard(t)
            takes.add(rel)
            return [t, rel, os.path.basename(t), os.path.basename(rel)], [], False
        elif edit == "swap-takes":
            other = rng.choice([x for x in sorted(takes) if x != t] or [t])
            a, b = rb(tp), rb(os.path.join(LIB, other))
            w(tp, b)
            w(os.path.join(LIB, other), a)
            return [t, other, os.path.basename(t), os.path.basename(other)], [], False
        return [t, os.path.basename(t)], [], False
    if edit in RESULT_EDITS:
        if not results:
            return [], [], True
        r = rng.choice(results)
        rp = os.path.join(D, r)
        hints = [r, os.path.basename(r), r[:-len(".json")], os.path.basename(r).split("@")[0].replace(".json", "")]
        if edit == "delete-result":
            os.unlink(rp)
        elif edit == "truncate-result":
            data = rb(rp)
            w(rp, data[:len(data) // 2])
        elif edit == "empty-result":
            w(rp, b"")
        elif edit == "copy-over-result":
            other = rng.choice([x for x in results if x != r] or [r])
            if other == r:
                w(rp, rb(rp).replace(b'"g":', b'"g": 0.5, "zz":', 1))
            else:
                shutil.copy(os.path.join(D, other), rp)
        elif edit == "other-model-result":
            take = None
            try:
                take = json.load(open(rp))["fit"]["reaches"][0]["clip"]
            except Exception:
                pass
            take = take if take and os.path.exists(os.path.join(ctx.dir, take)) else os.path.join(LIB, sorted(takes)[0])
            ctx.kin(["fit", take, "--model", "sb" if base[0] != "sb" else "sa", "--budget", "20", "--threads", "1",
                     "-q", "-o", rp], note="the edit: another model's fit over a result")
        elif edit == "edit-result-value":
            doc = json.load(open(rp))
            vals = doc.get("values", {})
            key = sorted(vals)[0] if vals else None
            if key:
                vals[key] = float(vals[key]) + 0.125
            doc["values"] = vals
            w(rp, json.dumps(doc, indent=2) + "\n")
        elif edit == "result-to-folder":
            os.unlink(rp)
            os.makedirs(rp)
        elif edit == "result-symlink":
            other = rng.choice([x for x in results if x != r] or [r])
            os.unlink(rp)
            os.symlink(os.path.relpath(os.path.join(D, other), os.path.dirname(rp)), rp)
        return hints, ([rp] if edit == "result-to-folder" else []), False
    # record edits
    if not recs:
        return [], [], True
    rec = rng.choice([x for x in recs if re.match(r"^\d+-of-\d+\.csv$", x)] or recs)
    recp = os.path.join(shards, rec)
    pair = [recp, recp[:-4] + ".json"]
    m = re.match(r"^(\d+)-of-(\d+)\.csv$", rec)
    shard_words = ["shard %s/%s" % m.groups()] if m else []
    if edit.startswith("stray:"):
        name = edit.split(":", 1)[1]
        src = recp if name.endswith(".csv") else recp[:-4] + ".json"
        shutil.copy(src, os.path.join(shards, name))
        return [name, "shards"], [os.path.join(shards, name)], False
    data = rb(recp)
    lines = data.split(b"\n")
    header = lines[0].decode("utf-8", "replace").split(",")
    rcol = header.index("result") if "result" in header else 6
    if edit == "empty-record":
        w(recp, b"")
    elif edit == "header-only-record":
        w(recp, lines[0] + b"\n")
    elif edit == "bom-record":
        w(recp, b"\xef\xbb\xbf" + data)
    elif edit == "extra-column-record":
        w(recp, b"\n".join(l + b",x" if l else l for l in lines))
    elif edit == "crlf-record":
        w(recp, data.replace(b"\n", b"\r\n"))
    elif edit == "dup-reach-row":
        rows = [l for l in lines if l.startswith(b"reach,")]
        if not rows:
            return [], [], True
        w(recp, data + rows[0] + b"\n")
        cells = rows[0].decode("utf-8", "replace").split(",")
        return [rec, rec[:-4], "shards"] + shard_words + [cells[1], cells[rcol]], pair, False
    elif edit in ("drop-take-row", "drop-reach-row"):
        pref = b"take," if edit == "drop-take-row" else b"reach,"
        rows = [i for i, l in enumerate(lines) if l.startswith(pref)]
        if not rows:
            return [], [], True
        k_ = rng.choice(rows)
        cells = lines[k_].decode("utf-8", "replace").split(",")
        del lines[k_]
        w(recp, b"\n".join(lines))
        return [rec, rec[:-4], "shards"] + shard_words + [x for x in (cells[1], cells[rcol] if len(cells) > rcol else "") if x], pair, False
    elif edit == "header-seed-edited":
        hp = recp[:-4] + ".json"
        txt = rb(hp)
        w(hp, re.sub(rb'"seed": \d+', b'"seed": 99', txt, count=1))
        return [rec[:-4], "shards", "seed", "header"] + shard_words, pair, False
    elif edit == "delete-header-json":
        os.unlink(recp[:-4] + ".json")
        return [rec[:-4], "shards", "header"] + shard_words, pair, False
    elif edit in ("delete-takes-json", "takes-json-size-edited"):
        tj = [x for x in os.listdir(shards) if x.startswith("takes-")]
        if not tj:
            return [], [], True
        tp = os.path.join(shards, tj[0])
        if edit == "delete-takes-json":
            os.unlink(tp)
        else:
            w(tp, re.sub(rb'"bytes": (\d+)', lambda m: b'"bytes": ' + str(int(m.group(1)) + 1).encode(), rb(tp), count=1))
        return [tj[0], "takes", "shards"], [shards], False
    elif edit == "foreign-record":
        src = os.path.join(FIX, "lib3.fits", "shards")
        name = "1-of-1" if N != 1 else "1-of-7"
        for f in os.listdir(src):
            if f.endswith(".csv") or re.match(r"^\d+-of-\d+\.json$", f):
                shutil.copy(os.path.join(src, f), os.path.join(shards, name + os.path.splitext(f)[1]))
            else:
                shutil.copy(os.path.join(src, f), os.path.join(shards, f))
        return [name, "shards", "root"], [os.path.join(shards, name + ".csv"), os.path.join(shards, name + ".json")], False
    return [rec, rec[:-4], "shards"] + shard_words, pair, False


def fam_take_edits(rng, n):
    fam = "02_take_edits"
    cases = []
    all_edits = TAKE_EDITS * 3 + RESULT_EDITS * 2 + RECORD_EDITS + BENIGN_EDITS * 2 + ["kill-shard"] * 4
    for i in range(n):
        edit = all_edits[i % len(all_edits)] if i < len(all_edits) else rng.choice(all_edits)
        N = rng.choice([1, 2, 2, 3, 4])
        j = rng.randint(1, N)
        ntakes = rng.randint(max(N, 4), 9)
        base = (rng.choice(["sa", "sa", "sb"]), rng.choice([20, 24, 30]))
        explicit_one = rng.random() < 0.5

        def fn(ctx, edit=edit, N=N, j=j, ntakes=ntakes, base=base, explicit_one=explicit_one,
               rng=random.Random(rng.random())):
            c = ctx.dir
            LIB = os.path.join(c, "LIB")
            takes = set(make_lib(LIB, rng, ntakes))
            D = os.path.join(c, "D")
            args = lib_args(*base)

            def shard_args(s, resume=False):
                sh = ["--shard", "%d/%d" % (s, N)] if (N > 1 or explicit_one) else []
                return ["fit", "LIB"] + args + ["--out-dir", "D"] + sh + (["--resume"] if resume else [])
            hints, undo, benign = [], [], True
            refused_shard = None
            for s in range(1, N + 1):
                if edit == "kill-shard" and s == j:
                    st = ctx.kin(shard_args(s), sig=(signal.SIGKILL, rng.uniform(0.02, 0.4)))
                    hints, benign = ["shard", "missing", "%d/%d" % (s, N), "resume"], False
                    continue
                st = ctx.kin(shard_args(s))
                if st.rc != 0:
                    if s > j and not benign:
                        if ctx.refused(st, hints=hints + ["changed", "takes"], what="a refusal of a changed library"):
                            refused_shard = s
                            continue
                    else:
                        ctx.succeeded(st, what="shard %d/%d" % (s, N))
                        return
                if s == j and edit != "kill-shard":
                    hints, undo, benign = apply_edit(ctx, edit, rng, LIB, D, N, takes, base)
            st = ctx.kin(["collect", "D"])
            if benign:
                if ctx.succeeded(st, what="collect after a harmless edit (%s)" % edit):
                    verify_library(ctx, D, LIB, args, st)
                return
            if st.rc == 0:
                verify_library(ctx, D, LIB, args, st)
                if ctx.findings:
                    return
            else:
                ctx.refused(st, hints=hints + (["shards"] if edit.startswith("stray") else []), codes=(1, 2),
                            what="collect naming what changed (%s)" % edit)
            # the remedy: undo the record damage, run every shard again with --resume, collect
            for u in undo:
                if os.path.isdir(u) and not os.path.islink(u):
                    shutil.rmtree(u, ignore_errors=True)
                elif os.path.lexists(u):
                    os.unlink(u)
            for s in range(1, N + 1):
                st = ctx.kin(shard_args(s, resume=True))
                if st.rc != 0:
                    ctx.find("bad_message", "the remedy (every shard again with --resume) failed at shard %d: %s" % (
                        s, st.text_err.strip()[:200]), st)
                    return
            st = ctx.kin(["collect", "D"])
            if st.rc == 0:
                verify_library(ctx, D, LIB, args, st, what="collect after the remedy")
            else:
                ctx.find("bad_message", "collect after the remedy exits %d: %s" % (st.rc, st.text_err.strip()[:200]), st)
        cases.append(Case(fam, "%s after shard %d of %d (%d takes, %s budget %d)" % (edit, j, N, ntakes, base[0], base[1]), fn))
    return cases


# ----------------------------------------------------------------------------- family 03

# (flag values, words a refusal must use, whether the setting changes the results)
SETTING_VARIANTS = [
    (["--seed", "2"], ["seed"], True), (["--seed", "18446744073709551615"], ["seed"], True),
    (["--optimizer", "dls"], ["optimizer"], True), (["--optimizer", "jt"], ["optimizer"], True),
    (["--optimizer", "njt"], ["optimizer"], True),
    (["--controller", "paper"], ["controller"], True),
    (["--objective", "positions+speed"], ["objective"], True),
    (["--objective", "positions+speed", "--speed-weight", "0.2"], ["objective", "speed"], True),
    (["MODEL", "sb"], ["model"], True), (["MODEL", "sc"], ["model"], True), (["MODEL", "se"], ["model"], True),
    (["BUDGET", "+1"], ["budget"], True), (["BUDGET", "*3"], ["budget"], True),
    (["--population", "9"], ["population"], True), (["--population", "4"], ["population"], True),
    (["--temperature", "0.5"], ["temperature"], True), (["--temperature", "0"], ["temperature"], True),
    (["--stable-change", "0.01"], ["stable-change", "stable_change", "stable change"], True),
    (["--stable-window", "25"], ["stable-window", "stable_window", "stable window"], True),
    (["--refine", "5"], ["refine"], True),
    (["--arm", "left"], ["arm"], True), (["--arm", "auto"], ["arm"], True),
    (["--select", "all"], ["select"], True), (["--select", "0"], ["select"], True),
    (["--frames", "5..60"], ["frames"], True),
    (["--fixed-base"], ["base", "fixed"], True),
    (["--from-unit", "cm"], ["--from-unit", "unit"], True), (["--from-unit", "m"], ["--from-unit", "unit"], True),
    (["--up", "z"], ["--up", " up"], True), (["--up", "y"], ["--up", " up"], True),
    (["--positions", "add"], ["--positions", "position"], True),
    (["--no-nested"], ["nested", "model"], True),
    (["--chain", "RightShoulder,RightArm,RightForeArm,RightHand"], ["chain", "arm"], True),
    (["SEGMENTS"], ["segments"], True),
    (["--warm-start"], ["warm_start", "warm-start", "warm start"], True),
    # the same settings, other spellings or other run options: must be accepted
    (["--threads", "2"], [], False), (["--json"], [], False), (["--seed", "1"], [], False),
    (["--seed", "01"], [], False), (["--stable-change", "0.001"], [], False), (["--stable-window", "15"], [], False),
    (["--temperature", "0.020"], [], False), (["--population", "8"], [], False), (["--controller", "smooth"], [], False),
    (["--objective", "positions"], [], False), (["--optimizer", "svd"], [], False), (["--arm", "right"], [], False),
    (["--max-input-mb", "4096"], [], False), (["--max-input-mb", "100"], [], False),
]


def fam_settings(rng, n):
    fam = "03_settings"
    cases = []
    for i in range(n):
        var = SETTING_VARIANTS[i % len(SETTING_VARIANTS)] if i < len(SETTING_VARIANTS) else rng.choice(SETTING_VARIANTS)
        N = rng.choice([2, 2, 3])
        odd = rng.randint(1, N)  # the shard run with the other setting
        first_normal = rng.randint(1, N) if odd == 1 else 1
        base_model = rng.choice(["sa", "sb"])
        budget = rng.choice([20, 24])
        via = rng.choice(["cli", "cli", "cli", "resume", "python"]) if PY else rng.choice(["cli", "cli", "resume"])

        def fn(ctx, var=var, N=N, odd=odd, base_model=base_model, budget=budget, via=via,
               rng=random.Random(rng.random())):
            flags, words, differs = var
            if flags[0] == "--no-nested" and base_model == "sa":
                differs = False  # S_A has no poorer model: nested or not, one fit
            c = ctx.dir
            LIB = os.path.join(c, "LIB")
            make_lib(LIB, rng, rng.randint(N + 1, 6), persons=["p01", "p02"])
            base = lib_args(base_model, budget)
            other = list(base)
            extra = []
            if flags[0] == "MODEL":
                other[other.index("--model") + 1] = flags[1] if flags[1] != base_model else "sc"
            elif flags[0] == "BUDGET":
                b = budget + 1 if flags[1] == "+1" else budget * 3
                other[other.index("--budget") + 1] = str(b)
            elif flags[0] == "SEGMENTS":
                subprocess.run([K, "segment", "LIB", "--select", "main", "-q", "--manifest", "seg.csv"],
                                          cwd=c, capture_output=True, timeout=120)
                extra = ["--segments", "seg.csv"]
            elif flags[0] == "--threads":
                other[other.index("--threads") + 1] = flags[1]
            else:
                extra = list(flags)
            other += extra
            odd_first = rng.random() < 0.4

            def run_shard(s, settings, python=False, resume=False):
                sh = "%d/%d" % (s, N)
                if python:
                    kw = py_kwargs_of(settings)
                    if kw is None:
                        return None
                    body = "_run(lambda: k.fit(%r, per='clip', out_dir='D', shard=%r, **%r) and None)" % ("LIB", sh, kw)
                    return ctx.py(body, timeout=120)
                return ctx.kin(["fit", "LIB"] + settings + ["--out-dir", "D", "--shard", sh] +
                               (["--resume"] if resume else []), timeout=120)
            D = os.path.join(c, "D")
            if odd_first:
                st = run_shard(odd, other)
                if st.rc == 1 and "nothing to fit" in st.text_err:
                    pass  # e.g. --arm left on right-handed takes: skipped, and recorded
                elif not ctx.succeeded(st, what="the first shard (%s)" % " ".join(flags)):
                    return
                normal = [s for s in range(1, N + 1) if s != odd]
                st = run_shard(normal[0], base, python=(via == "python"), resume=(via == "resume"))
                if st is None:
                    st = run_shard(normal[0], base)
                if differs:
                    before = set(library_results(D))
                    if ctx.refused(st, hints=words, what="a refusal of a shard with other settings than the first"):
                        if set(library_results(D)) != before:
                            ctx.find("wrong_exit0", "the refused shard wrote results", st)
                        st2 = ctx.kin(["collect", "D"])
                        if st2.rc == 0:
                            ctx.find("data_loss", "collect 'complete' after a refused shard", st2)
                    elif st.rc == 0 or (st.result or {}).get("ok"):
                        for s in normal[1:]:
                            run_shard(s, base)
                        st2 = ctx.kin(["collect", "D"])
                        if st2.rc == 0:
                            ctx.find("data_loss", "collect 'complete' over shards of different settings (%s)" % " ".join(flags), st2)
                    return
                if not ctx.succeeded(st, what="a shard with the same settings (%s)" % " ".join(flags)):
                    return
                for s in normal[1:]:
                    if not ctx.succeeded(run_shard(s, base), what="shard %d/%d" % (s, N)):
                        return
            else:
                for s in range(1, N + 1):
                    if s != odd and not ctx.succeeded(run_shard(s, base), what="shard %d/%d" % (s, N)):
                        return
                st = run_shard(odd, other, python=(via == "python"), resume=(via == "resume"))
                if st is None:
                    st = run_shard(odd, other)
                if differs:
                    before = set(library_results(D))
                    if ctx.refused(st, hints=words, what="a refusal of a shard with other settings"):
                        if set(library_results(D)) != before:
                            ctx.find("wrong_exit0", "the refused shard wrote results", st)
                        st2 = ctx.kin(["collect", "D"])
                        if st2.rc == 0:
                            ctx.find("data_loss", "collect 'complete' with shard %d/%d never run with the library's settings" % (odd, N), st2)
                        st3 = run_shard(odd, base)
                        if ctx.succeeded(st3, what="the refused shard with the library's settings"):
                            st4 = ctx.kin(["collect", "D"])
                            if ctx.succeeded(st4, what="collect of a whole library"):
                                verify_library(ctx, D, LIB, base, st4)
                    elif st.rc == 0 or (st.result or {}).get("ok"):
                        st4 = ctx.kin(["collect", "D"])
                        if st4.rc == 0:
                            ctx.find("data_loss", "collect 'complete' over shards of different settings (%s)" % " ".join(flags), st4)
                    return
                if not ctx.succeeded(st, what="a shard with the same settings (%s)" % " ".join(flags)):
                    return
            st = ctx.kin(["collect", "D"])
            if ctx.succeeded(st, what="collect of shards of the same settings"):
                verify_library(ctx, D, LIB, base, st)
        cases.append(Case(fam, "shard %d/%d with %s (%s, via %s)" % (odd, N, " ".join(var[0]), "refuse" if var[2] else "same",
                                                                    via), fn, needs_py=(via == "python")))
    return cases


def py_kwargs_of(cli):
    """Python keyword arguments for CLI library flags (None: no Python spelling)."""
    kw = {}
    i = 0
    names = {"--model": "model", "--budget": "budget", "--threads": "threads", "--seed": "seed",
             "--optimizer": "optimizer", "--controller": "controller", "--objective": "objective",
             "--speed-weight": "speed_weight", "--population": "population", "--temperature": "temperature",
             "--stable-change": "stable_change", "--stable-window": "stable_window", "--refine": "refine",
             "--arm": "arm", "--select": "select", "--from-unit": "unit", "--up": "up", "--positions": "positions",
             "--segments": "segments"}
    ints = {"budget", "threads", "seed", "population", "stable_window", "refine"}
    floats = {"speed_weight", "temperature", "stable_change"}
    while i < len(cli):
        a = cli[i]
        if a in ("--per", ):
            i += 2
            continue
        if a in ("-q", "--json"):
            i += 1
            continue
        if a == "--fixed-base":
            kw["fixed_base"] = True
            i += 1
            continue
        if a == "--no-nested":
            kw["nested"] = False
            i += 1
            continue
        if a == "--warm-start":
            kw["warm_start"] = True
            i += 1
            continue
        if a == "--frames":
            x, y = cli[i + 1].split("..")
            kw["frames"] = (int(x), int(y))
            i += 2
            continue
        if a == "--chain":
            kw["chain"] = cli[i + 1].split(",")
            i += 2
            continue
        if a not in names:
            return None
        k_, v = names[a], cli[i + 1]
        kw[k_] = int(v) if k_ in ints else float(v) if k_ in floats else v
        if k_ == "select" and v.isdigit():
            kw[k_] = int(v)
        i += 2
    return kw


# ----------------------------------------------------------------------------- family 04


def fam_resume(rng, n):
    fam = "04_resume"
    cases = []
    dsp = ["D", "./D", "D/../D", "ABS", "D/", "D//", "./D/.", "Dlink", "Dlink/", "ABSlink"]
    lsp = ["LIB", "./LIB", "LIB/../LIB", "ABS", "LIB/", "LIBlink", "LIB/./", "persons", "files"]
    cwds = ["case", "elsewhere", "root"]
    damage = ["none", "none", "delete-some", "kill"]
    for i in range(n):
        d_s, l_s, cw, dm = rng.choice(dsp), rng.choice(lsp), rng.choice(cwds), rng.choice(damage)
        via = "python" if (PY and rng.random() < 0.2) else "cli"
        first_d = rng.choice(["D", "ABS", "./D/"])
        model = rng.choice(["sa", "sb"])

        def fn(ctx, d_s=d_s, l_s=l_s, cw=cw, dm=dm, via=via, first_d=first_d, model=model,
               rng=random.Random(rng.random())):
            c = ctx.dir
            LIB = os.path.join(c, "LIB")
            takes = make_lib(LIB, rng, rng.randint(4, 8), persons=["p01", "p02"])
            os.symlink("D", os.path.join(c, "Dlink"))
            os.symlink("LIB", os.path.join(c, "LIBlink"))
            os.makedirs(os.path.join(c, "elsewhere"))
            D = os.path.join(c, "D")
            args = lib_args(model, 24)
            fd = D if first_d == "ABS" else first_d
            if dm == "kill":
                ctx.kin(["fit", "LIB"] + args + ["--out-dir", fd], sig=(signal.SIGKILL, rng.uniform(0.05, 0.6)))
            else:
                st = ctx.kin(["fit", "LIB"] + args + ["--out-dir", fd])
                if not ctx.succeeded(st, what="the first run"):
                    return
            deleted = []
            if dm == "delete-some":
                res = library_results(D)
                deleted = rng.sample(res, rng.randint(1, max(1, len(res) // 2)))
                for r in deleted:
                    os.unlink(os.path.join(D, r))
            before = {k: v for k, v in file_stats(D).items() if k in library_results(D)}
            # spell the paths from the run's folder
            cwd = {"case": c, "elsewhere": os.path.join(c, "elsewhere"), "root": "/"}[cw]

            def spell(s, name):
                if s.startswith("ABS"):
                    return os.path.join(c, name + ("link" if s == "ABSlink" else ""))
                p = s.replace("LIB", name) if name == "LIB" else s
                full = os.path.join(c, p)
                if cw == "case":
                    return p
                if cw == "root":
                    return full
                rel = os.path.relpath(os.path.join(c, p.split("/")[0]), cwd)
                rest = p[len(p.split("/")[0]):]
                return rel + rest
            dpath = spell(d_s, "D")
            if l_s == "persons":
                lpaths = [spell("LIB", "LIB") + "/p01", spell("LIB", "LIB") + "/p02"]
            elif l_s == "files":
                lpaths = [spell("LIB", "LIB") + "/" + t for t in sorted(takes)]
            else:
                lpaths = [spell(l_s, "LIB")]
            if via == "python":
                body = "_run(lambda: k.fit(%r, per='clip', model=%r, budget=24, threads=1, out_dir=%r, resume=True) and None)" % (
                    lpaths if len(lpaths) > 1 else lpaths[0], model, dpath)
                st = ctx.py(body, cwd=cwd, timeout=120)
            else:
                st = ctx.kin(["fit"] + lpaths + args + ["--out-dir", dpath, "--resume"], cwd=cwd, timeout=120)
            ok = (st.rc == 0) if st.kind == "kin" else bool((st.result or {}).get("ok"))
            if not ok:
                if l_s in ("persons", "files") and st.rc == 2 or (st.kind == "py" and l_s in ("persons", "files")):
                    ctx.refused(st, hints=["takes", "settings", "folder", "changed"], what="a refusal of takes given otherwise")
                    return
                ctx.succeeded(st, what="--resume spelled %s / %s from %s" % (d_s, l_s, cw))
                return
            after = file_stats(D)
            if dm != "kill":
                rewritten = [k for k, v in before.items() if after.get(k) != v]
                if rewritten:
                    ctx.find("wrong_exit0", "--resume (%s, %s, from %s) fitted again %d of %d complete results, e.g. %s" % (
                        d_s, l_s, cw, len(rewritten), len(before), rewritten[0]), st)
            missing = [r for r in deleted if not os.path.exists(os.path.join(D, r))]
            if missing:
                ctx.find("data_loss", "--resume did not fit the deleted results again: %s" % missing[:3], st)
            st2 = ctx.kin(["collect", "D"])
            if ctx.succeeded(st2, what="collect after --resume"):
                verify_library(ctx, D, LIB, args, st2)
        cases.append(Case(fam, "%s, first -o %s, resume D=%s LIB=%s from %s via %s (%s)" % (
            dm, first_d, d_s, l_s, cw, via, model), fn, needs_py=(via == "python")))
    return cases


# ----------------------------------------------------------------------------- family 05

LINK_KINDS = ["self", "parent", "root-abs", "loop2", "loop2dirs", "sibling", "filedup", "dangling", "outside",
              "chain", "deep-self"]


def make_links(LIB, kind, c):
    if kind == "self":
        os.symlink(".", os.path.join(LIB, "p01", "again"))
    elif kind == "parent":
        os.symlink("..", os.path.join(LIB, "p01", "up"))
    elif kind == "root-abs":
        os.symlink(LIB, os.path.join(LIB, "p02", "top"))
    elif kind == "loop2":
        os.symlink("b", os.path.join(LIB, "a"))
        os.symlink("a", os.path.join(LIB, "b"))
    elif kind == "loop2dirs":
        os.makedirs(os.path.join(LIB, "x"))
        os.makedirs(os.path.join(LIB, "y"))
        os.symlink("../y", os.path.join(LIB, "x", "l"))
        os.symlink("../x", os.path.join(LIB, "y", "l"))
        shutil.copy(ds("p03/r01.bvh"), os.path.join(LIB, "x", "t.bvh"))
    elif kind == "sibling":
        os.symlink("p01", os.path.join(LIB, "p03"))
    elif kind == "filedup":
        first = sorted(os.listdir(os.path.join(LIB, "p01")))[0]
        os.symlink(first, os.path.join(LIB, "p01", "dup.bvh"))
    elif kind == "dangling":
        os.symlink("nowhere.bvh", os.path.join(LIB, "p01", "gone.bvh"))
    elif kind == "outside":
        os.makedirs(os.path.join(c, "EXT"))
        shutil.copy(ds("p04/r01.bvh"), os.path.join(c, "EXT", "e.bvh"))
        os.symlink("../EXT", os.path.join(LIB, "ext"))
    elif kind == "chain":
        os.symlink("l2", os.path.join(LIB, "l1"))
        os.symlink("l3", os.path.join(LIB, "l2"))
        os.symlink("p01", os.path.join(LIB, "l3"))
    elif kind == "deep-self":
        os.makedirs(os.path.join(LIB, "p02", "d1", "d2"))
        os.symlink("../../..", os.path.join(LIB, "p02", "d1", "d2", "back"))


def reachable_takes(LIB):
    """(canonical files found without following links, canonical files reachable through links)."""
    nofollow, follow = set(), set()
    for base, _d, fn in os.walk(LIB, followlinks=False):
        for f in fn:
            p = os.path.join(base, f)
            if f.endswith(".bvh") and not os.path.islink(p) and os.path.isfile(p):
                nofollow.add(os.path.realpath(p))
    seen_dirs = set()
    stack = [LIB]
    while stack:
        d = stack.pop()
        rd = os.path.realpath(d)
        if rd in seen_dirs:
            continue
        seen_dirs.add(rd)
        try:
            names = os.listdir(d)
        except OSError:
            continue
        for nm in names:
            p = os.path.join(d, nm)
            if os.path.isdir(p):
                stack.append(p)
            elif nm.endswith(".bvh") and os.path.isfile(p):
                follow.add(os.path.realpath(p))
    return nofollow, follow


def fam_links(rng, n):
    fam = "05_links"
    cases = []
    cmds = ["fit-library", "fit-person", "segment", "segment-manifest", "compare", "style"]
    for i in range(n):
        kinds = [rng.choice(LINK_KINDS)]
        if rng.random() < 0.35:
            kinds.append(rng.choice(LINK_KINDS))
        kinds = list(dict.fromkeys(kinds))
        cmd = cmds[i % len(cmds)]

        def fn(ctx, kinds=kinds, cmd=cmd, rng=random.Random(rng.random())):
            c = ctx.dir
            LIB = os.path.join(c, "LIB")
            for t in ("p01/r01.bvh", "p01/r02.bvh", "p02/r03.bvh"):
                os.makedirs(os.path.join(LIB, os.path.dirname(t)), exist_ok=True)
                shutil.copy(ds(t), os.path.join(LIB, t))
            for k_ in kinds:
                make_links(LIB, k_, c)
            nofollow, follow = reachable_takes(LIB)
            lo, hi = len(nofollow), len(follow)
            before = snap(LIB)
            quick = ["--budget", "20", "--threads", "1"]
            if cmd == "fit-library":
                st = ctx.kin(["fit", "LIB", "--per", "clip", "--model", "sa", "-q", "--out-dir", "D"] + quick, timeout=60)
            elif cmd == "fit-person":
                st = ctx.kin(["fit", "LIB", "--model", "sa", "-q", "-o", "p.json"] + quick, timeout=60)
            elif cmd == "segment":
                st = ctx.kin(["segment", "LIB", "--select", "main", "--json"], timeout=60)
            elif cmd == "segment-manifest":
                st = ctx.kin(["segment", "LIB", "--select", "main", "-q", "--manifest", "s.csv"], timeout=60)
            elif cmd == "compare":
                st = ctx.kin(["compare", "LIB", "--models", "sa", "--optimizers", "svd", "--no-baselines", "-q",
                              "-o", "cmp"] + quick, timeout=60)
            else:
                st = ctx.kin(["style", "LIB", "--params", os.path.join(FIX, "p_sa.json"), "--json", "-o", "st"], timeout=90)
            if snap(LIB) != before:
                ctx.find("data_loss", "the library folder changed", st)
            if st.timed_out:
                return
            if st.rc != 0:
                if st.rc == 2:
                    ctx.refused(st, hints=["link", "loop", "LIB", "again", "up", "top", "/a", "/b", "l1", "p03",
                                           "dup", "gone", "ext", "back"], what="a refusal naming the link")
                else:
                    ctx.succeeded(st, what="a folder with links (%s)" % ",".join(kinds))
                return
            # count each capture once
            clips = []
            if cmd == "fit-library":
                rows, problems = read_library(os.path.join(c, "D"), base=c)
                for p in problems[:2]:
                    ctx.find("data_loss", p, st)
                clips = [os.path.realpath(os.path.join(LIB, k_[0])) for k_ in (rows or {})]
            elif cmd == "fit-person":
                try:
                    doc = json.load(open(os.path.join(c, "p.json")))
                    clips = [os.path.realpath(os.path.join(c, r["clip"])) for r in doc["fit"]["reaches"]]
                except Exception as e:
                    ctx.find("wrong_exit0", "p.json does not read: %r" % e, st)
            elif cmd == "segment":
                try:
                    doc = json.loads(st.text_out)
                    doc = doc if isinstance(doc, list) else [doc]
                    clips = [os.path.realpath(os.path.join(c, d.get("clip") or d.get("path") or "?")) for d in doc]
                except Exception as e:
                    ctx.find("wrong_exit0", "segment --json does not parse: %r" % e, st)
            elif cmd == "segment-manifest":
                lines = [l for l in open(os.path.join(c, "s.csv"), newline="").read().split("\n") if l and not l.startswith("#")]
                for r in list(csv.DictReader(io.StringIO("\n".join(lines)))):
                    clips.append(os.path.realpath(os.path.join(c, r["clip"])))
            elif cmd == "compare":
                for r in csv.DictReader(open(os.path.join(c, "cmp", "results.csv"), newline="")):
                    if r.get("model") == "sa" and r.get("optimizer", "svd") == "svd" and r.get("method", "annealing") in ("annealing", "simulated_annealing", ""):
                        clips.append(os.path.realpath(os.path.join(c, r.get("clip", "?"))))
                # every capture has as many rows as every other: a capture taken twice has twice as many
                per = {}
                for r in csv.DictReader(open(os.path.join(c, "cmp", "results.csv"), newline="")):
                    x = os.path.realpath(os.path.join(c, r.get("clip", "?")))
                    per[x] = per.get(x, 0) + 1
                if per and max(per.values()) != min(per.values()):
                    x = max(per, key=per.get)
                    ctx.find("wrong_exit0", "compare's results.csv has %d rows of %s, %d of another capture" % (
                        per[x], os.path.relpath(x, c), min(per.values())), st)
                clips = []
            else:
                try:
                    doc = json.loads(st.text_out)
                    rows = doc.get("rows", []) if isinstance(doc, dict) else doc
                    clips = [os.path.realpath(os.path.join(c, r.get("clip", "?"))) for r in rows if isinstance(r, dict)]
                except Exception:
                    clips = []
            counts = {}
            for x in clips:
                counts[x] = counts.get(x, 0) + 1
            dup = {x: k_ for x, k_ in counts.items() if k_ > 1}
            if dup:
                x, k_ = next(iter(dup.items()))
                ctx.find("wrong_exit0", "%s counts the capture %s %d times (links %s)" % (
                    cmd, os.path.relpath(x, c), k_, ",".join(kinds)), st)
            distinct = len(counts)
            if cmd in ("fit-library", "fit-person") and distinct and not (lo <= distinct <= hi):
                ctx.find("wrong_exit0", "%d distinct captures fitted, the folder has %d (%d through links)" % (distinct, lo, hi), st)
        cases.append(Case(fam, "%s on a folder with links %s" % (cmd, "+".join(kinds)), fn))
    return cases


# ----------------------------------------------------------------------------- family 06

ENV_VALUES = ["0", "1", "2", "3", "100000", "100001", "4000000", "4000001", "9223372036854775808",
              "18446744073709551616", "99999999999999999999999", "1e10", "10000000000", "-1", "-0", "+1", " 1", "1 ",
              "", "abc", "1.5", "0x10", "\uff11", "\t2\n", b"\xff", "2" * 60]
SHARD_VALUES = ["1/1", "1/2", "2/2", "0/1", "1/0", "2/1", "1/100000", "100000/100000", "1/100001", "100001/100001",
                "-1/2", "1/2/3", "a/b", "1 / 2", "01/2", "1/02", "+1/2", "18446744073709551616/1",
                "1/9223372036854775808", "", "/", "1/", "/1", "1/1e10", "1.0/2", "\uff11/2", " 1/2", "1/2 ",
                "99999999999999999999999/1", "1/3", "3/3", "1\\2", "1-2", "1 of 2"]
RECORD_NAMES = ["2-of-1.csv", "0-of-1.csv", "01-of-1.csv", "1-of-01.csv", "1-of-99999999999.csv", "1-of-1000000.csv",
                "1-of-100001.csv", "100001-of-100001.csv", "1-of-18446744073709551616.csv", "0-of-0.csv",
                "-1-of-1.csv", "1-of-2.csv", "2-of-2.csv", "1-of-100000.csv", "100000-of-100000.csv", "2-of-1.json",
                "1-of-1000000.json", "1-of-99999999999.json", "1-of-1.CSV", "1-of-1.csv.bak", "notes.txt",
                "1-of-1 .csv", "1-0f-1.csv", "+1-of-1.csv", "1-of-" + "9" * 200 + ".csv", ".1-of-1.csv.123.tmp"]


def slurm_number(v, low, high):
    if isinstance(v, bytes):
        return None
    s = v.strip()
    if not re.match(r"^\+?[0-9]+$", s):
        return None
    x = int(s)
    return x if low <= x <= high else None


def slurm_expect(idv, minv, cntv):
    """'whole' (no array job), ('shard', i, n) or ('refuse', variable)."""
    if idv is None:
        return ("whole",)
    if isinstance(idv, bytes):
        return ("refuse", "SLURM_ARRAY_TASK_ID")
    i = slurm_number(idv, 0, 4000000)
    if i is None:
        return ("refuse", "SLURM_ARRAY_TASK_ID")
    if minv is None or isinstance(minv, bytes):
        return ("refuse", "SLURM_ARRAY_TASK_MIN")
    m = slurm_number(minv, 0, 4000000)
    if m is None:
        return ("refuse", "SLURM_ARRAY_TASK_MIN")
    if cntv is None or isinstance(cntv, bytes):
        return ("refuse", "SLURM_ARRAY_TASK_COUNT")
    n = slurm_number(cntv, 1, 100000)
    if n is None:
        return ("refuse", "SLURM_ARRAY_TASK_COUNT")
    if i < m or i - m + 1 > n:
        return ("refuse", "SLURM_ARRAY_TASK_ID")
    return ("shard", i - m + 1, n)


def shard_expect(text):
    if "/" not in text:
        return None
    a, b = text.split("/", 1)
    a, b = a.strip(), b.strip()

    def num(t):
        if not t or len(t) > 20 or not all(ch in "0123456789" for ch in t):
            return None
        x = int(t)
        return x if 1 <= x <= 100000 else None
    i, n = num(a), num(b)
    if i is None or n is None or i > n:
        return None
    return (i, n)


def fam_bounds(rng, n):
    fam = "06_bounds"
    cases = []
    n_env = n * 45 // 100
    n_shard = n * 25 // 100
    n_rec = n * 20 // 100
    n_py = n - n_env - n_shard - n_rec
    for i in range(n_env):
        vals = {}
        valid = {"SLURM_ARRAY_TASK_ID": rng.choice(["1", "2", "3", "0"]), "SLURM_ARRAY_TASK_MIN": rng.choice(["0", "1"]),
                 "SLURM_ARRAY_TASK_COUNT": rng.choice(["3", "4", "100000"])}
        vals.update(valid)
        for var in rng.sample(list(valid), rng.choice([1, 1, 1, 2])):
            vals[var] = rng.choice(ENV_VALUES)
        if rng.random() < 0.1:
            del vals[rng.choice(["SLURM_ARRAY_TASK_MIN", "SLURM_ARRAY_TASK_COUNT"])]
        with_shard = rng.random() < 0.1

        def fn(ctx, vals=vals, with_shard=with_shard):
            c = ctx.dir
            shutil.copytree(os.path.join(FIX, "lib3"), os.path.join(c, "LIB"))
            exp = ("shard", 1, 2) if with_shard else slurm_expect(vals.get("SLURM_ARRAY_TASK_ID"),
                                                                   vals.get("SLURM_ARRAY_TASK_MIN"),
                                                                   vals.get("SLURM_ARRAY_TASK_COUNT"))
            st = ctx.kin(["fit", "LIB"] + lib_args("sa", 20) + ["--out-dir", "D"] + (["--shard", "1/2"] if with_shard else []),
                         env=vals, timeout=60)
            if exp[0] == "refuse":
                if ctx.refused(st, hints=[exp[1]], what="a refusal of %s" % exp[1]):
                    if os.path.exists(os.path.join(c, "D", "shards")) and os.listdir(os.path.join(c, "D", "shards")):
                        ctx.find("wrong_exit0", "the refused run wrote shard records", st)
                return
            if not ctx.succeeded(st, what="a valid array task %r" % (exp,)):
                return
            recs = sorted(x for x in os.listdir(os.path.join(c, "D", "shards")) if x.endswith(".csv"))
            want = "1-of-1.csv" if exp[0] == "whole" else "%d-of-%d.csv" % (exp[1], exp[2])
            if recs != [want]:
                ctx.find("wrong_exit0", "records %s, expected %s for %s" % (recs, want, vals), st)
        label = " ".join("%s=%r" % (k_[len("SLURM_ARRAY_TASK_"):], v if len(v) < 24 else v[:6] + "...(%d)" % len(v))
                         for k_, v in sorted(vals.items()))
        cases.append(Case(fam, "env %s%s" % (label, " with --shard 1/2" if with_shard else ""), fn))
    for i in range(n_shard):
        text = SHARD_VALUES[i % len(SHARD_VALUES)] if i < len(SHARD_VALUES) else rng.choice(SHARD_VALUES)
        env = {"SLURM_ARRAY_TASK_ID": "9223372036854775808", "SLURM_ARRAY_TASK_MIN": "x",
               "SLURM_ARRAY_TASK_COUNT": "1e10"} if rng.random() < 0.2 else None

        def fn(ctx, text=text, env=env):
            c = ctx.dir
            shutil.copytree(os.path.join(FIX, "lib3"), os.path.join(c, "LIB"))
            exp = shard_expect(text)
            st = ctx.kin(["fit", "LIB"] + lib_args("sa", 20) + ["--out-dir", "D", "--shard=" + text], env=env, timeout=60)
            if exp is None:
                ctx.refused(st, hints=["--shard"], what="a refusal of --shard %r" % text)
                return
            if ctx.succeeded(st, what="--shard %r" % text):
                recs = sorted(x for x in os.listdir(os.path.join(c, "D", "shards")) if x.endswith(".csv"))
                want = "%d-of-%d.csv" % exp
                if recs != [want]:
                    ctx.find("wrong_exit0", "records %s, expected %s" % (recs, want), st)
        cases.append(Case(fam, "--shard %r%s" % (text, " (absurd Slurm variables set too)" if env else ""), fn))
    for i in range(n_rec):
        name = RECORD_NAMES[i % len(RECORD_NAMES)] if i < len(RECORD_NAMES) else rng.choice(RECORD_NAMES)
        content = rng.choice(["copy", "copy", "empty", "garbage", "huge-header"])

        def fn(ctx, name=name, content=content):
            c = ctx.dir
            shutil.copytree(os.path.join(FIX, "lib3"), os.path.join(c, "LIB"))
            shutil.copytree(os.path.join(FIX, "lib3.fits"), os.path.join(c, "D"))
            # the fixture library's root is FIX/lib3: it must be found where its takes are
            shards = os.path.join(c, "D", "shards")
            srcname = "1-of-1.csv" if name.lower().endswith(".csv") or not name.endswith(".json") else "1-of-1.json"
            if content == "copy":
                data = rb(os.path.join(shards, srcname))
            elif content == "empty":
                data = b""
            elif content == "garbage":
                data = b"kind,clip\nshard,\x00\xff\n"
            else:
                data = b"kind,clip,person,arm,onset,end,result,blake3,seconds,why\n" + b"take,x,,,,,,,,\n" * 20000
            ctx.echo = [name[:-4]] if len(name) > 30 else []
            try:
                w(os.path.join(shards, name), data)
            except OSError as e:
                ctx.find("bad_message", "the sweep could not make %r: %r" % (name[:40], e))
                return
            before = snap(os.path.join(c, "D", "library.csv"))
            st = ctx.kin(["collect", "D"], timeout=60)
            benign = name in ("1-of-1.csv.bak", "notes.txt", "1-of-1.CSV", "1-of-1 .csv", "1-0f-1.csv", ".1-of-1.csv.123.tmp")
            if name in ("1-of-2.csv", "2-of-2.csv"):
                benign = False
            if st.rc == 0:
                rows, problems = read_library(os.path.join(c, "D"))
                n_rows = len(rows or {})
                for p in problems[:2]:
                    ctx.find("data_loss", p, st)
                raw = list(csv.DictReader(open(os.path.join(c, "D", "library.csv"), newline="")))
                if len(raw) != 3:
                    ctx.find("data_loss", "collect 'complete' with %d rows for 3 reaches (stray %s)" % (len(raw), name[:40]), st)
                elif not benign:
                    ctx.find("wrong_exit0", "collect 'complete' with a stray record %s" % name[:40], st)
                return
            if benign:  # an unrelated file in shards/: a run, or a refusal naming it
                ctx.refused(st, hints=[name], codes=(1, 2), what="collect beside an unrelated file %r" % name)
                return
            short = name if len(name) < 60 else name[:10]
            ctx.refused(st, hints=[short, name.split(".")[0][:12], "shards"], codes=(1, 2),
                        what="a refusal of the record %s" % name[:40])
        cases.append(Case(fam, "collect with shards/%s (%s)" % (name if len(name) < 50 else name[:10] + "...(%d)" % len(name), content), fn))
    py_shards = ["'1/2'", "(1, 2)", "(2, 2)", "(0, 1)", "(2, 1)", "(1, 100001)", "(1, 100000)", "(2**64, 1)",
                 "(-1, 2)", "('1', '2')", "1.5", "'1/0'", "'0/0'", "(1, 2, 3)", "''", "'1/100001'", "[1, 2]", "True",
                 "(1, 2**63)", "'1/2/3'"]
    for i in range(n_py):
        expr = py_shards[i % len(py_shards)]

        def fn(ctx, expr=expr):
            c = ctx.dir
            shutil.copytree(os.path.join(FIX, "lib3"), os.path.join(c, "LIB"))
            body = "_run(lambda: k.fit('LIB', per='clip', model='sa', budget=20, threads=1, out_dir='D', shard=%s) and None)" % expr
            st = ctx.py(body, timeout=60)
            try:
                v = eval(expr)
            except Exception:
                v = None
            text = None
            if isinstance(v, str):
                text = v
            elif isinstance(v, (tuple, list)) and len(v) == 2 and all(isinstance(x, int) and not isinstance(x, bool) for x in v):
                text = "%d/%d" % tuple(v) if all(x >= 0 for x in v) else None
            exp = shard_expect(text) if text is not None else None
            if isinstance(v, list) and (st.result or {}).get("ok"):
                return  # a list for the documented tuple: taken as one, fine
            if exp is None or isinstance(v, list):
                ctx.refused(st, hints=["shard"], what="a refusal of shard=%s" % expr)
            else:
                ctx.succeeded(st, what="shard=%s" % expr)
        cases.append(Case(fam, "python fit(out_dir=..., shard=%s)" % expr, fn, needs_py=True))
    return cases


# ----------------------------------------------------------------------------- family 07

SIGINT_KINDS = [
    ("cli-compare-sd", False), ("cli-compare-baselines", False), ("cli-fit-window", False),
    ("cli-fit-refine", False), ("cli-fit-library", False), ("cli-fit-field", False), ("cli-compare-library-takes", False),
    ("py-fit", True), ("py-fit-refine", True), ("py-compare", True), ("py-compare-nobaselines", True),
    ("py-fork-fit", True), ("py-fit-progress", True), ("py-fit-library", True), ("py-thread-fit", True),
]


def fam_sigint(rng, n):
    fam = "07_sigint"
    cases = []
    for i in range(n):
        kind, is_py = SIGINT_KINDS[i % len(SIGINT_KINDS)]
        delay = rng.uniform(1.0, 4.0)
        threads = rng.choice([1, 2])

        def fn(ctx, kind=kind, delay=delay, threads=threads):
            c = ctx.dir
            clip = ds("p01/r09.bvh")
            p01 = ds("p01")
            th = ["--threads", str(threads)]
            long_fit = ["--budget", "1000000", "--stable-window", "100000"]
            single = None
            if kind == "cli-compare-sd":
                st = ctx.kin(["compare", clip, "--models", "sd", "--optimizers", "svd", "--no-baselines", "-q", "-o", "R"]
                             + long_fit + th, sig=(signal.SIGINT, delay))
            elif kind == "cli-compare-baselines":
                st = ctx.kin(["compare", clip, "--models", "sa", "--optimizers", "svd", "--budget", "1000000", "-q", "-o", "R"]
                             + th, sig=(signal.SIGINT, delay))
            elif kind == "cli-fit-window":
                single = "out.json"
                st = ctx.kin(["fit", clip, "--model", "se", "-q", "-o", single] + long_fit + th, sig=(signal.SIGINT, delay))
            elif kind == "cli-fit-refine":
                single = "out.json"
                st = ctx.kin(["fit", p01, "--model", "sc", "--budget", "300", "--refine", "10000000", "-q", "-o", single] + th,
                             sig=(signal.SIGINT, delay))
            elif kind == "cli-fit-library":
                st = ctx.kin(["fit", p01, "--per", "clip", "--model", "sd", "-q", "--out-dir", "D"] + long_fit + th,
                             sig=(signal.SIGINT, delay))
            elif kind == "cli-fit-field":
                single = "field.json"
                st = ctx.kin(["fit", p01, "--model", "sc", "--field", "-q", "-o", single] + long_fit + th,
                             sig=(signal.SIGINT, delay))
            elif kind == "cli-compare-library-takes":
                st = ctx.kin(["compare", p01, "--models", "sa,sb,sc,sd", "--optimizers", "jt,njt,svd", "-q", "-o", "R",
                              "--budget", "4000"] + th, sig=(signal.SIGINT, delay))
            else:
                body = {
                    "py-fit": "_run(lambda: k.fit(%r, model='sd', budget=10**6, stable_window=100000, threads=%d) and None)" % (clip, threads),
                    "py-fit-refine": "_run(lambda: k.fit(%r, model='sc', budget=300, refine=10**7, threads=%d) and None)" % (p01, threads),
                    "py-compare": "_run(lambda: k.compare(%r, models=['sa'], optimizers=['svd'], budget=10**6, threads=%d) and None)" % (clip, threads),
                    "py-compare-nobaselines": "_run(lambda: k.compare(%r, models=['sd'], optimizers=['svd'], baselines=False, budget=10**6, stable_window=100000, threads=%d) and None)" % (clip, threads),
                    "py-fork-fit": ("import multiprocessing as mp\n"
                                    "def work(q):\n"
                                    "    k.fit(%r, model='sd', budget=10**6, stable_window=100000, threads=%d)\n"
                                    "    q.put('done')\n"
                                    "k.fit(%r, model='sa', budget=20, threads=1)\n"
                                    "def main():\n"
                                    "    ctx = mp.get_context('fork'); q = ctx.Queue(); p = ctx.Process(target=work, args=(q,))\n"
                                    "    p.start()\n"
                                    "    try:\n"
                                    "        p.join()\n"
                                    "    finally:\n"
                                    "        p.join(10)\n"
                                    "    return p.exitcode\n"
                                    "_run(main)") % (clip, threads, clip),
                    "py-fit-progress": "_run(lambda: k.fit(%r, model='sd', budget=10**6, stable_window=100000, threads=%d, progress=lambda d: None) and None)" % (clip, threads),
                    "py-fit-library": "_run(lambda: k.fit(%r, per='clip', model='sd', budget=10**6, stable_window=100000, threads=%d, out_dir='D') and None)" % (p01, threads),
                    "py-thread-fit": ("import threading\nres = {}\n"
                                      "def work():\n"
                                      "    try:\n        k.fit(%r, model='sd', budget=10**6, stable_window=100000, threads=%d)\n"
                                      "    except BaseException as e:\n        res['e'] = e\n"
                                      "t = threading.Thread(target=work, daemon=True); t.start()\n"
                                      "def main():\n"
                                      "    while t.is_alive():\n        t.join(0.1)\n"
                                      "    return 'thread ended'\n"
                                      "_run(main)") % (clip, threads),
                }[kind]
                st = ctx.py(body, sig=(signal.SIGINT, delay), timeout=60)
            if st.label == "finished before the signal":
                if st.rc != 0 and not (st.result or {}).get("ok"):
                    ctx.succeeded(st, what="a long run before the signal")
                return
            if st.timed_out:
                return
            if st.kind == "kin":
                if st.rc == 0 and "interrupt" not in (st.text_err + st.text_out).lower():
                    ctx.find("wrong_exit0", "ignored Ctrl-C: exit 0 %.1f s after the signal" % (st.stop or 0), st)
                elif st.rc is not None and st.rc > 0 and "interrupt" not in st.text_err.lower():
                    ctx.find("bad_message", "exit %d after Ctrl-C without saying it was interrupted" % st.rc, st)
                if single and os.path.exists(os.path.join(c, single)) and st.rc != 0:
                    ctx.find("wrong_exit0", "interrupted (exit %s) but %s was written" % (st.rc, single), st)
                if kind == "cli-fit-library":
                    for r in library_results(os.path.join(c, "D")):
                        try:
                            json.load(open(os.path.join(c, "D", r)))
                        except Exception as e:
                            ctx.find("data_loss", "interrupted library left a broken result %s: %r" % (r, e), st)
                    st2 = ctx.kin(["collect", "D"])
                    if st2.rc == 0:
                        ctx.find("data_loss", "collect 'complete' after an interrupted library run", st2)
            else:
                r = st.result or {}
                if r.get("ok"):
                    ctx.find("wrong_exit0", "Python call returned %r %.1f s after Ctrl-C" % (r.get("value"), st.stop or 0), st)
                elif r.get("exc") not in ("KeyboardInterrupt",) and st.rc != -signal.SIGINT:
                    ctx.find("bad_message", "Ctrl-C surfaced as %s: %s" % (r.get("exc"), (r.get("msg") or "")[:150]), st)
            if st.stop is not None and st.stop > 3.0:
                ctx.find("hang", "took %.1f s to stop after Ctrl-C (limit 3 s)" % st.stop, st)
        cases.append(Case(fam, "%s, Ctrl-C at %.1f s, threads %d" % (kind, delay, threads), fn, needs_py=is_py))
    return cases


# ----------------------------------------------------------------------------- family 08

# parameter: (CLI flag or None, kind, low, high)
PY_PARAMS = {
    "budget": ("--budget", "int", 1, 10 ** 7),
    "population": ("--population", "int", 1, 1000),
    "temperature": ("--temperature", "float", 0.0, 1e6),
    "stable_change": ("--stable-change", "float", 0.0, 1.0),
    "stable_window": ("--stable-window", "int", 1, 100000),
    "refine": ("--refine", "int", 1, 10 ** 7),
    "threads": ("--threads", "int", 1, 1024),
    "speed_weight": ("--speed-weight", "float", 0.0, 10.0),
    "seed": ("--seed", "int", 0, 2 ** 64 - 1),
}


def candidates(kind, lo, hi):
    vals = [lo, hi]
    if kind == "int":
        vals += [lo - 1, hi + 1, hi * 10, -1, 0, 2 ** 63, 2 ** 64, -2 ** 63, 1.5, float(lo), "5", None, True, float("nan")]
    else:
        vals += [math.nextafter(lo, -math.inf), math.nextafter(hi, math.inf), hi + 1, hi * 1.0001 if hi else 1e-9,
                 -1.0, -0.0, float("nan"), float("inf"), -float("inf"), 1e308, 5e-324, "0.5", None, 1]
    return vals


def py_expect(kind, lo, hi, v):
    """'accept', 'refuse' or 'any' for value v of a parameter."""
    if v is None:
        return "any"  # None: the default where the stub allows it, a TypeError where not
    if isinstance(v, bool):
        return "any"
    if isinstance(v, str):
        return "any"
    if kind == "int":
        if isinstance(v, float):
            if not math.isfinite(v) or not (lo <= v <= hi):
                return "refuse"
            return "any"
        return "accept" if lo <= v <= hi else "refuse"
    if not math.isfinite(float(v)):
        return "refuse"
    return "accept" if lo <= float(v) <= hi else "refuse"


def fam_py_strict(rng, n):
    fam = "08_py_strict"
    cases = []
    items = []
    for name, (flag, kind, lo, hi) in PY_PARAMS.items():
        for v in candidates(kind, lo, hi):
            items.append(("fit", name, v))
            if flag and not isinstance(v, (str, type(None), bool)):
                items.append(("cli", name, v))
    for v in [50.0001, 50.0, 0.001, 0.0009999, 0.05, 0.049, 0.01, 0.0, -0.0, -1.0, float("nan"), float("inf"), 1e-300,
              1e300, 49.99999, 0.0010001]:
        items.append(("segment", "min_peak_speed", v))
        items.append(("cli-segment", "min_peak_speed", v))
    for what in ["from_arrays-0", "from_arrays-1", "with_values-0", "with_values-1", "with_values-nan", "with_values-shape",
                 "with_values-ft0", "with_values-ft-neg", "with_values-ft-nan", "with_values-ft-inf", "from_arrays-ft0",
                 "from_arrays-nonunit-quat", "from_arrays-nan", "slice-empty", "slice-reversed", "slice-beyond"]:
        items.append(("clip", what, None))
    for what in ["compare-budget-10**7+1", "compare-population-1001", "compare-stable_window-100001", "compare-temperature-1e6+1",
                 "compare-stable_change-1.0001", "synthesize-tolerance-0", "synthesize-tolerance-1.0001",
                 "synthesize-max_seconds-60.001", "synthesize-max_seconds-0.001", "reach-flexibility-nan", "reach-height-0",
                 "reach-height-100", "plan-budget_ms-0", "hand_speed-smoothing-nan", "read_bvh-max_input_mb-0",
                 "read_bvh-max_input_mb-4097", "fit-frames-reversed", "fit-select--1"]:
        items.append(("misc", what, None))
    rng.shuffle(items)
    if n < len(items):
        items = items[:n]
    clip = None
    for where, name, v in items:
        def fn(ctx, where=where, name=name, v=v):
            clip = ds("p01/r09.bvh")
            if where in ("fit", "cli"):
                flag, kind, lo, hi = PY_PARAMS[name]
                exp = py_expect(kind, lo, hi, v)
                budget = 20
                if name == "population" and isinstance(v, int) and not isinstance(v, bool) and 20 < v <= 1000:
                    budget = v
                kw = {"model": "sa" if name != "refine" else "sa", "threads": 1}
                if name != "budget":
                    kw["budget"] = budget
                kw.pop(name, None)
                if name == "speed_weight":
                    kw["objective"] = "positions+speed"
                if name == "budget" and isinstance(v, int) and v > 2000 and exp == "accept":
                    kw["stable_window"] = 2  # an accepted huge budget ends by the stopping rule
                if name == "refine" and exp == "accept" and isinstance(v, int) and v > 500:
                    kw["stable_window"] = 2
                if where == "fit":
                    body = "_run(lambda: k.fit(%r, %s=%r, **%r).distances)" % (clip, name, v, kw) if not isinstance(v, float) or math.isfinite(v) \
                        else "_run(lambda: k.fit(%r, %s=float(%r), **%r).distances)" % (clip, name, repr(v), kw)
                    st = ctx.py(body, timeout=120)
                else:
                    args = ["fit", clip, "--model", kw["model"], "-q", "-o", "o.json"] + (
                        ["--threads", "1"] if name != "threads" else [])
                    if "budget" in kw:
                        args += ["--budget", str(kw["budget"])]
                    if "objective" in kw:
                        args += ["--objective", kw["objective"]]
                    if "stable_window" in kw:
                        args += ["--stable-window", str(kw["stable_window"])]
                    sv = repr(v) if isinstance(v, float) else str(v)
                    args += ["%s=%s" % (flag, sv)]
                    st = ctx.kin(args, timeout=120)
                if exp == "refuse":
                    ctx.refused(st, hints=[name, flag, name.replace("_", " ")], what="a refusal of %s=%r" % (name, v))
                elif exp == "accept":
                    # the lower budget bound: at least the population (8), as the CLI says
                    if name == "budget" and isinstance(v, int) and v < 8:
                        ctx.refused(st, hints=["budget"], what="a refusal of budget %d < population" % v)
                    else:
                        ctx.succeeded(st, what="%s=%r" % (name, v))
                else:
                    if not (st.rc == 0 or (st.result or {}).get("ok")):
                        ctx.refused(st, hints=[name, flag, "argument", "int", "float", "integer"], codes=(2,),
                                    what="a refusal of %s=%r" % (name, v))
                return
            if where in ("segment", "cli-segment"):
                ok = math.isfinite(v) and 0.001 <= v <= 50
                if where == "segment":
                    st = ctx.py("_run(lambda: len(k.segment(k.read_bvh(%r), min_peak_speed=float(%r))))" % (clip, repr(v)))
                else:
                    st = ctx.kin(["segment", clip, "--min-peak-speed=%r" % v])
                if ok:
                    ctx.succeeded(st, what="min_peak_speed=%r (documented 0.001 to 50)" % v)
                else:
                    ctx.refused(st, hints=["min_peak_speed", "--min-peak-speed", "min-peak-speed"],
                                what="a refusal of min_peak_speed=%r" % v)
                return
            if where == "clip":
                pre = ("c = k.read_bvh(%r)\nv = c.values\n"
                       "A = (c.joint_names, c.parents, c.offsets)\n") % clip
                body = {
                    "from_arrays-0": "_run(lambda: k.Clip.from_arrays(c.joint_names, c.parents, c.offsets, c.rotations[:0], c.root_translation[:0], c.frame_time).frame_count)",
                    "from_arrays-1": "_run(lambda: k.Clip.from_arrays(c.joint_names, c.parents, c.offsets, c.rotations[:1], c.root_translation[:1], c.frame_time).frame_count)",
                    "with_values-0": "_run(lambda: c.with_values(v[:0]).frame_count)",
                    "with_values-1": "_run(lambda: c.with_values(v[:1]).frame_count)",
                    "with_values-nan": "vv = v.copy(); vv[3, 4] = float('nan')\n_run(lambda: c.with_values(vv).to_bvh()[:10])",
                    "with_values-shape": "_run(lambda: c.with_values(v[:, :-1]).frame_count)",
                    "with_values-ft0": "_run(lambda: c.with_values(v, frame_time=0.0).frame_count)",
                    "with_values-ft-neg": "_run(lambda: c.with_values(v, frame_time=-0.01).frame_count)",
                    "with_values-ft-nan": "_run(lambda: c.with_values(v, frame_time=float('nan')).frame_count)",
                    "with_values-ft-inf": "_run(lambda: c.with_values(v, frame_time=float('inf')).frame_count)",
                    "from_arrays-ft0": "_run(lambda: k.Clip.from_arrays(c.joint_names, c.parents, c.offsets, c.rotations, c.root_translation, 0.0).frame_count)",
                    "from_arrays-nonunit-quat": "_run(lambda: k.Clip.from_arrays(c.joint_names, c.parents, c.offsets, c.rotations * 2.0, c.root_translation, c.frame_time).to_bvh()[:10])",
                    "from_arrays-nan": "r = c.rotations.copy(); r[2, 1, 0] = float('nan')\n_run(lambda: k.Clip.from_arrays(c.joint_names, c.parents, c.offsets, r, c.root_translation, c.frame_time).frame_count)",
                    "slice-empty": "_run(lambda: c.slice(5, 5).frame_count)",
                    "slice-reversed": "_run(lambda: c.slice(9, 3).frame_count)",
                    "slice-beyond": "_run(lambda: c.slice(0, 10**6).frame_count)",
                }[name]
                st = ctx.py(pre + body)
                accept = name in ("from_arrays-1", "with_values-1")
                if name == "from_arrays-nonunit-quat" and (st.result or {}).get("ok"):
                    return  # normalized or refused: both are fine
                if accept:
                    ctx.succeeded(st, what=name)
                else:
                    ctx.refused(st, hints=["frame", "value", "rotation", "quaternion", "nan", "finite", "shape", "slice",
                                           "start", "end", "column", "time"], what="a refusal (%s)" % name)
                return
            # misc
            fn_, arg, val = name.split("-", 2)
            bodies = {
                "compare": "_run(lambda: k.compare(%r, models=['sa'], optimizers=['svd'], baselines=False, threads=1, %s=%s) and None)",
                "synthesize": "_run(lambda: k.synthesize(%r, k.Params.load(%r), %s=%s).frame_count)",
                "reach": "_run(lambda: k.reach([0.3, 1.1, 0.4], %s=%s).frame_count)",
                "plan": "_run(lambda: k.plan(%r, target=[-0.25, 1.1, 0.3], %s=%s).frame_count)",
                "hand_speed": "_run(lambda: len(k.hand_speed(%r, %s=%s)))",
                "read_bvh": "_run(lambda: k.read_bvh(%r, %s=%s).frame_count)",
                "fit": "_run(lambda: k.fit(%r, model='sa', budget=20, threads=1, %s=%s).distances)",
            }
            val_expr = {"10**7+1": "10**7+1", "1001": "1001", "100001": "100001", "1e6+1": "1e6+1", "1.0001": "1.0001",
                        "0": "0", "60.001": "60.001", "0.001": "0.001", "nan": "float('nan')", "100": "100.0",
                        "4097": "4097", "reversed": "(50, 10)", "-1": "-1", "none": "None"}[val]
            if fn_ == "synthesize":
                body = bodies[fn_] % (clip, os.path.join(FIX, "p_sa.json"), arg, val_expr)
            elif fn_ == "reach":
                body = bodies[fn_] % (arg, val_expr)
            elif fn_ == "plan":
                body = bodies[fn_] % (os.path.join(BOOKSHELF, "scene.json"), arg, val_expr)
            else:
                body = bodies[fn_] % (clip, arg, val_expr)
            st = ctx.py(body, timeout=120)
            ctx.refused(st, hints=[arg, arg.replace("_", " ")], what="a refusal (%s)" % name)
        lab = "%s %s=%r" % (where, name, v) if where in ("fit", "cli", "segment", "cli-segment") else "%s %s" % (where, name)
        cases.append(Case(fam, lab, fn, needs_py=where not in ("cli", "cli-segment")))
    return cases


# ----------------------------------------------------------------------------- family 09

CELL_VALUES = [("NaN", "refuse"), ("nan", "refuse"), ("inf", "refuse"), ("-inf", "refuse"), ("+inf", "refuse"),
               ("Infinity", "refuse"), ("-1", "refuse"), ("-1e-9", "refuse"), ("-0", "any"), ("0", "accept"),
               ("1e-300", "accept"), ("1e300", "refuse"), ("1e308", "refuse"), ("1e309", "refuse"), ("abc", "refuse"),
               ("0x10", "refuse"), (" 0.05", "any"), ("5e-324", "accept"), ("1_0", "refuse"), ("", "any")]
TABLE_EDITS = ["all-empty-row", "all-empty-table", "mixed-model", "mixed-optimizer", "mixed-settings", "dup-row",
               "no-header", "empty-file", "header-only", "bom", "crlf", "missing-column", "extra-column",
               "person-pipe", "person-newline", "person-backtick", "short-row", "empty-clip", "library-folder",
               "library-missing", "huge-row-count"]
COLLECT_EDITS = ["result-dotdot", "result-absolute", "blake3-other", "unknown-kind", "shard-hash", "header-unknown-field",
                 "header-format-2", "header-truncated", "takes-truncated", "record-folder", "header-root-elsewhere",
                 "nul-in-record", "invalid-utf8-record", "reach-of-unknown-take", "huge-onset", "unknown-arm"]


def md_table_problems(text):
    probs = []
    lines = text.split("\n")
    i = 0
    while i < len(lines):
        if lines[i].startswith("|") and i + 1 < len(lines) and re.match(r"^\|(\s*:?-+:?\s*\|)+\s*$", lines[i + 1]):
            ncols = lines[i].count("|") - lines[i].count("\\|")
            j = i + 2
            while j < len(lines) and lines[j].startswith("|"):
                nc = lines[j].count("|") - lines[j].count("\\|")
                if nc != ncols and "`" not in lines[j]:
                    probs.append("table row %r has %d cells, header %d" % (lines[j][:80], nc - 1, ncols - 1))
                j += 1
            if j < len(lines) and not lines[j - 1].rstrip().endswith("|"):
                probs.append("table row %r is cut" % lines[j - 1][:80])
            i = j
        else:
            i += 1
    return probs


def fam_tables(rng, n):
    fam = "09_tables"
    cases = []
    items = [("cell", v, e) for v, e in CELL_VALUES] * 2 + [("table", t, None) for t in TABLE_EDITS] + \
        [("collect", t, None) for t in COLLECT_EDITS]
    while len(items) < n:
        items.append(rng.choice(items))
    items = items[:n]
    for kind, what, exp in items:
        def fn(ctx, kind=kind, what=what, exp=exp, rng=random.Random(rng.random())):
            c = ctx.dir
            D = os.path.join(c, "D")
            shutil.copytree(os.path.join(FIX, "lib6.fits"), D)
            lc = os.path.join(D, "library.csv")
            text = open(lc, newline="").read()
            rows = list(csv.reader(io.StringIO(text)))
            hdr, body = rows[0], rows[1:]
            dcols = [j for j, h in enumerate(hdr) if h in ("distance_sa_m", "distance_sb_m", "distance_sc_m")]
            hints = ["library.csv"]
            if kind == "collect":
                shards = os.path.join(D, "shards")
                rec = os.path.join(shards, "1-of-1.csv")
                head = os.path.join(shards, "1-of-1.json")
                data = rb(rec)
                lines = data.split(b"\n")
                reach_i = [i for i, l in enumerate(lines) if l.startswith(b"reach,")]
                ri = rng.choice(reach_i)
                cells = lines[ri].split(b",")
                # The record's columns by name, from its header (a column added moves the rest).
                col = {name: j for j, name in enumerate(lines[0].decode().split(","))}
                ONSET, RESULT, BLAKE3, ARM = col["onset"], col["result"], col["blake3"], col["arm"]
                hints = ["1-of-1", "shards", "record"]
                if what == "result-dotdot":
                    cells[RESULT] = b"../../../../etc/hostname"
                elif what == "result-absolute":
                    cells[RESULT] = os.path.join(D, "library.csv").encode()
                elif what == "blake3-other":
                    other = lines[rng.choice([i for i in reach_i if i != ri] or [ri])].split(b",")
                    cells[BLAKE3] = other[BLAKE3]
                elif what == "unknown-kind":
                    cells[0] = b"reech"
                elif what == "huge-onset":
                    cells[ONSET] = b"9" * 40
                elif what == "reach-of-unknown-take":
                    cells[1] = b"p07/r99.bvh"
                elif what == "unknown-arm":
                    cells[ARM] = b"9" * 40
                if what in ("result-dotdot", "result-absolute", "blake3-other", "unknown-kind", "huge-onset",
                            "reach-of-unknown-take", "unknown-arm"):
                    lines[ri] = b",".join(cells)
                    w(rec, b"\n".join(lines))
                elif what == "shard-hash":
                    shard = rb"(shard" + b"," * RESULT + rb"1-of-1\.json,)([0-9a-f])"
                    w(rec, re.sub(shard, lambda m: m.group(1) + (b"0" if m.group(2) != b"0" else b"1"), data))
                elif what == "header-unknown-field":
                    w(head, rb(head).replace(b"{", b'{\n  "zz": 1,', 1))
                elif what == "header-format-2":
                    w(head, rb(head).replace(b'"kinergy_library": 1', b'"kinergy_library": 2'))
                elif what == "header-truncated":
                    w(head, rb(head)[:len(rb(head)) // 2])
                elif what == "takes-truncated":
                    tj = [x for x in os.listdir(shards) if x.startswith("takes-")][0]
                    w(os.path.join(shards, tj), rb(os.path.join(shards, tj))[:100])
                    hints.append(tj)
                elif what == "record-folder":
                    os.unlink(rec)
                    os.makedirs(rec)
                elif what == "header-root-elsewhere":
                    w(head, re.sub(rb'"root": "[^"]*"', b'"root": "/nonexistent/lib"', rb(head)))
                    hints += ["/nonexistent", "root", "takes"]
                elif what == "nul-in-record":
                    w(rec, data.replace(b"reach,", b"reach\x00,", 1))
                elif what == "invalid-utf8-record":
                    w(rec, data.replace(b"reach,p0", b"reach,\xff\xfe0", 1))
                before = snap(lc)
                st = ctx.kin(["collect", "D"], timeout=60)
                if st.rc == 0:
                    ok = verify_library(ctx, D, os.path.join(FIX, "lib6"), lib_args("sc", 24), st)
                    if ok and what not in ():
                        ctx.find("wrong_exit0", "collect 'complete' over a damaged record (%s)" % what, st)
                    return
                ctx.refused(st, hints=hints, codes=(1, 2), what="a refusal of a damaged record (%s)" % what)
                if st.rc == 2 and snap(lc) != before:
                    ctx.find("wrong_exit0", "collect refused (exit 2) but rewrote library.csv", st)
                return
            expect = "refuse"
            if kind == "cell":
                r = rng.randrange(len(body))
                col = rng.choice(dcols)
                body[r][col] = what
                expect = exp
                hints = [hdr[col]]  # the promise: the row and the column named
                if what == "" and col == dcols[-1]:
                    expect = "refuse"  # the richest model's own distance
            else:
                if what == "all-empty-row":
                    r = rng.randrange(len(body))
                    for j in dcols:
                        body[r][j] = ""
                    hints += ["row", "line", "empty", "distance"]
                elif what == "all-empty-table":
                    for r in body:
                        for j in dcols:
                            r[j] = ""
                    hints += ["empty", "distance"]
                elif what == "mixed-model":
                    body[rng.randrange(len(body))][hdr.index("model")] = rng.choice(["sa", "sd"])
                    hints += ["model"]
                elif what == "mixed-optimizer":
                    body[rng.randrange(len(body))][hdr.index("optimizer")] = rng.choice(["jt", "dls"])
                    hints += ["optimizer"]
                elif what == "mixed-settings":
                    body[rng.randrange(len(body))][hdr.index("settings")] = "0123456789abcdef"
                    hints += ["settings"]
                elif what == "dup-row":
                    body.append(list(body[0]))
                    expect = "any"
                elif what == "no-header":
                    rows = body
                    hdr = None
                elif what == "empty-file":
                    rows, hdr = [], None
                elif what == "header-only":
                    body = []
                elif what in ("bom", "crlf", "extra-column", "huge-row-count"):
                    expect = "any"
                elif what == "missing-column":
                    j = rng.choice(dcols[:-1] + [hdr.index("person"), hdr.index("model")])
                    hints.append(hdr[j])
                    hdr = hdr[:j] + hdr[j + 1:]
                    body = [r[:j] + r[j + 1:] for r in body]
                elif what in ("person-pipe", "person-newline", "person-backtick"):
                    val = {"person-pipe": "a|b", "person-newline": "a\nb", "person-backtick": "a`b"}[what]
                    for r in body:
                        if r[hdr.index("person")] == "p01":
                            r[hdr.index("person")] = val
                    expect = "any"
                elif what == "short-row":
                    body[rng.randrange(len(body))].pop()
                    hints += ["row", "line", "column"]
                elif what == "empty-clip":
                    body[rng.randrange(len(body))][hdr.index("clip")] = ""
                    expect = "any"
                elif what == "library-folder":
                    pass
                elif what == "library-missing":
                    pass
            buf = io.StringIO()
            wr = csv.writer(buf, lineterminator="\r\n" if what == "crlf" else "\n")
            if hdr is not None:
                wr.writerow(hdr + (["extra"] if what == "extra-column" else []))
            if what == "huge-row-count":
                body = body * 3000
            for r in body:
                wr.writerow(r + (["x"] if what == "extra-column" else []))
            out = buf.getvalue()
            if what == "bom":
                out = "\ufeff" + out
            if what == "library-folder":
                os.unlink(lc)
                os.makedirs(lc)
            elif what == "library-missing":
                os.unlink(lc)
            else:
                w(lc, out.encode("utf-8"))
            st = ctx.kin(["compare", "--library", "D", "-o", "R", "--json"], timeout=60)
            if st.rc == 0:
                if expect == "refuse":
                    ctx.find("wrong_exit0", "compare --library summarised a table that cannot be true (%s %r)" % (kind, what), st)
                    return
                sm = os.path.join(c, "R", "summary.md")
                if not os.path.exists(sm):
                    ctx.find("wrong_exit0", "exit 0 but no summary.md", st)
                    return
                text = open(sm, encoding="utf-8", errors="replace").read()
                for where, t in (("summary.md", text), ("stdout", st.text_out)):
                    bad = nonfinite(t) or long_number(t)
                    if bad:
                        ctx.find("wrong_exit0", "%s: %s" % (where, bad), st)
                        break
                for p in md_table_problems(text)[:1]:
                    ctx.find("wrong_exit0", "summary.md: %s" % p, st)
                if re.search(r"\|\s*(—|-|–)\s*\|\s*(—|-|–)\s*\|", text) and what == "all-empty-table":
                    ctx.find("wrong_exit0", "a table of dashes", st)
                return
            if expect == "accept":
                ctx.succeeded(st, what="compare --library on a table with %s %r" % (kind, what))
                return
            ctx.refused(st, hints=hints, what="a refusal of library.csv (%s %r)" % (kind, what))
        cases.append(Case(fam, "%s %s" % ("collect" if kind == "collect" else "compare --library, " + kind, repr(what)), fn))
    return cases


# ----------------------------------------------------------------------------- family 10


def fam_options(rng, n):
    fam = "10_options"
    cases = []
    items = []
    for v in ["0", "0.05", "0.2", "10", "10.01", "-1", "nan", "inf"]:
        for where in ["fit", "fit-library", "compare", "py-fit", "py-compare"]:
            items.append(("speed-weight", where, v))
    for i in range(14):
        items.append(("controller-paper", rng.choice(["synthesize", "synthesize-override", "py-synthesize", "reach",
                                                      "style", "plan", "py-synthesize-override"]), "r%02d" % (i + 1)))
    for where in ["segment", "segment-manifest", "segment-json", "py-segment", "segment-right-control",
                  "segment-world-control", "fit-world?"]:
        items.append(("world-auto", where, None))
    rng.shuffle(items)
    while len(items) < n:
        items.append(rng.choice(items))
    items = items[:n]
    for what, where, v in items:
        def fn(ctx, what=what, where=where, v=v, rng=random.Random(rng.random())):
            c = ctx.dir
            clip = ds("p01/r09.bvh")
            if what == "speed-weight":
                with_obj = rng.random() < 0.35
                obj = ["--objective", "positions+speed"] if with_obj else rng.choice([[], ["--objective", "positions"]])
                valid = with_obj and v in ("0", "0.05", "0.2", "10")
                q_ = ["--budget", "20", "--threads", "1", "-q"]
                if where == "fit":
                    st = ctx.kin(["fit", clip, "--model", "sa", "--speed-weight=" + v, "-o", "o.json"] + obj + q_)
                elif where == "fit-library":
                    st = ctx.kin(["fit", ds("p01/r01.bvh"), clip, "--per", "clip", "--model", "sa", "--speed-weight=" + v,
                                  "--out-dir", "D"] + obj + q_)
                elif where == "compare":
                    st = ctx.kin(["compare", clip, "--models", "sa", "--optimizers", "svd", "--no-baselines",
                                  "--speed-weight=" + v, "-o", "R"] + obj + q_)
                else:
                    kw = {"budget": 20, "threads": 1, "speed_weight": float(v)}
                    if obj:
                        kw["objective"] = obj[1]
                    if where == "py-fit":
                        body = "_run(lambda: k.fit(%r, model='sa', **%s).record.get('objective'))" % (clip, repr(kw).replace("nan", "float('nan')").replace("inf", "float('inf')"))
                    else:
                        body = "_run(lambda: k.compare(%r, models=['sa'], optimizers=['svd'], baselines=False, **%s) and None)" % (clip, repr(kw).replace("nan", "float('nan')").replace("inf", "float('inf')"))
                    st = ctx.py(body)
                if valid:
                    if ctx.succeeded(st, what="--speed-weight %s with positions+speed" % v) and where == "fit":
                        doc = open(os.path.join(c, "o.json")).read()
                        if "positions+speed" not in doc and "speed_weight" not in doc:
                            ctx.find("wrong_exit0", "the parameters file records no objective", st)
                else:
                    ctx.refused(st, hints=["--speed-weight", "speed_weight", "speed-weight"],
                                what="a refusal of --speed-weight %s %s" % (v, " ".join(obj) or "without --objective"))
                return
            if what == "controller-paper":
                take = ds("p01/%s.bvh" % v)
                st = ctx.kin(["fit", take, "--model", "sc", "--controller", "paper", "--budget", "40", "--threads", "1",
                              "--per", "clip", "-q", "-o", "paper.json"])
                if not ctx.succeeded(st, what="fit --controller paper"):
                    return
                doc = json.load(open(os.path.join(c, "paper.json")))
                fit_d = doc["fit"]["score_m"]
                if "paper" not in json.dumps(doc):
                    ctx.find("wrong_exit0", "the parameters file does not record the controller paper", st)
                if where in ("synthesize", "synthesize-override"):
                    extra = ["--controller", "smooth"] if where.endswith("override") else []
                    st = ctx.kin(["synthesize", take, "--params", "paper.json", "--frames", "fit", "--json", "-o", "s.bvh"] + extra)
                    if st.rc == 1 and "not reached" in st.text_err:
                        pass  # a replay that stalls, as its fit did: the report still says how
                    elif not ctx.succeeded(st, what="synthesize --params paper.json"):
                        return
                    try:
                        rep = json.loads(st.text_out)
                    except ValueError:
                        ctx.find("wrong_exit0", "synthesize --json is not JSON", st)
                        return
                    ctrl = rep.get("controller")
                    dist = rep.get("distance_to_capture_m", rep.get("distance_m"))
                    if where == "synthesize":
                        if ctrl != "paper":
                            ctx.find("wrong_exit0", "synthesize --json reports controller %r for a paper fit" % ctrl, st)
                        if dist is None:
                            ctx.find("wrong_exit0", "synthesize --json reports no distance (keys %s)" % sorted(rep)[:12], st)
                        elif abs(float(dist) - fit_d) > 1e-9 + 1e-6 * fit_d:
                            ctx.find("wrong_exit0", "replayed distance %.6f m, the fit's %.6f m" % (float(dist), fit_d), st)
                    else:
                        if ctrl != "smooth":
                            ctx.find("wrong_exit0", "--controller smooth asked, report says %r" % ctrl, st)
                        if "paper" not in st.text_err and "controller" not in st.text_err:
                            ctx.find("wrong_exit0", "replaying a paper fit under smooth says nothing", st)
                elif where in ("py-synthesize", "py-synthesize-override"):
                    extra = ", controller='smooth'" if where.endswith("override") else ""
                    st = ctx.py("def f():\n    try:\n        return k.synthesize(%r, k.Params.load('paper.json'), frames='fit'%s).report\n"
                                "    except k.UnreachableError as e:\n        return e.clip.report\n_run(f)" % (take, extra))
                    if not ctx.succeeded(st, what="Python synthesize of a paper fit"):
                        return
                    rep = (st.result or {}).get("value") or {}
                    ctrl = rep.get("controller") if isinstance(rep, dict) else None
                    if not extra and ctrl != "paper":
                        ctx.find("wrong_exit0", "Python synthesize reports controller %r for a paper fit" % ctrl, st)
                    if extra and not (st.result or {}).get("warnings"):
                        ctx.find("wrong_exit0", "Python synthesize under another controller warns of nothing", st)
                    dist = rep.get("distance_to_capture_m", rep.get("distance_m")) if isinstance(rep, dict) else None
                    if not extra and dist is not None and abs(float(dist) - fit_d) > 1e-9 + 1e-6 * fit_d:
                        ctx.find("wrong_exit0", "replayed distance %.6f m, the fit's %.6f m" % (float(dist), fit_d), st)
                else:
                    args = {"reach": ["reach", "--target", "0.3,1.1,0.4", "--params", "paper.json", "--json", "-o", "r.bvh"],
                            "style": ["style", take, "--params", "paper.json", "--json"],
                            "plan": ["plan", "--scene", os.path.join(BOOKSHELF, "scene.json"), "--target", "-0.25,1.1,0.3",
                                     "--budget-ms", "300", "--params", "paper.json", "--json", "-o", "p.bvh"]}[where]
                    st = ctx.kin(args, timeout=120)
                    if st.rc == 1:
                        return  # a task that did not reach: not this case's question
                    if ctx.succeeded(st, what="%s --params of a paper fit" % where):
                        m = re.search(r'"controller":\s*"(\w+)"', st.text_out)
                        if m and m.group(1) != "paper":
                            ctx.find("wrong_exit0", "%s --json says controller %s for a paper fit" % (where, m.group(1)), st)
                        if "controller" in st.text_err.lower():
                            ctx.find("wrong_exit0", "%s warns of another controller for a paper fit: %s" % (
                                where, st.text_err.strip()[:150]), st)
                return
            # segment --world --arm auto
            if where == "segment":
                st = ctx.kin(["segment", ds("p01"), "--world", "--arm", "auto"])
            elif where == "segment-manifest":
                st = ctx.kin(["segment", clip, "--arm", "auto", "--world", "--manifest", "s.csv"])
            elif where == "segment-json":
                st = ctx.kin(["segment", clip, "--world", "--arm=auto", "--json", "--select", "all"])
            elif where == "py-segment":
                st = ctx.py("_run(lambda: k.segment(%r, world=True, arm='auto'))" % clip)
            elif where == "segment-right-control":
                st = ctx.kin(["segment", clip, "--world", "--arm", "right"])
                ctx.succeeded(st, what="segment --world --arm right")
                return
            elif where == "segment-world-control":
                st = ctx.kin(["segment", clip, "--arm", "auto"])
                ctx.succeeded(st, what="segment --arm auto")
                return
            else:
                st = ctx.kin(["fit", clip, "--world", "--arm", "auto", "--model", "sa", "-o", "o.json"])
                ctx.refused(st, hints=["--world"], what="a refusal of fit --world")
                return
            ctx.refused(st, hints=["--world", "world"], what="a refusal of --world with --arm auto")
            if where == "segment-manifest" and os.path.exists(os.path.join(c, "s.csv")):
                ctx.find("wrong_exit0", "refused but wrote s.csv", st)
        cases.append(Case(fam, "%s %s %s" % (what, where, v or ""), fn, needs_py=where.startswith("py-")))
    return cases


# ----------------------------------------------------------------------------- family 11


def bvh_with_value(src, value, where):
    """The capture src with one channel value of a middle frame replaced by `value` (text)."""
    data = rb(src).decode("latin-1")
    head, motion = data.split("MOTION", 1)
    lines = motion.split("\n")
    first = next(i for i, l in enumerate(lines) if l.startswith("Frame Time:")) + 1
    k = first + (len([l for l in lines[first:] if l.strip()]) // 2)
    vals = lines[k].split()
    j = {"root-pos": 0, "rotation": 10, "last": len(vals) - 1}[where]
    vals[j] = value
    lines[k] = " ".join(vals)
    return (head + "MOTION" + "\n".join(lines)).encode("latin-1")


def fam_messages(rng, n):
    fam = "11_messages"
    cases = []
    items = []
    for b in [1, 7, 8, 16, 19, 20, 21]:
        items += [("budget", "cli", b), ("budget", "py", b)]
    for v in ["1e-300", "1e300", "1e308", "-1e308", "5e-324", "1e-30", "123456789012345678901234567890123", "1e309", "nan"]:
        for where in ["root-pos", "rotation"]:
            for cmd in ["convert", "inspect", "segment-json", "segment-manifest", "fit", "py-to_bvh"]:
                items.append(("bvh-number", cmd, (v, where)))
    for v in ["1e300", "1e-300", "1e308", "5e-324", "-1e308", "1e-30"]:
        for cmd in ["synthesize", "py-load", "reach"]:
            items.append(("params-number", cmd, v))
    for v in ["1e-300", "1e300", "5e-324"]:
        items.append(("with_values-number", "py", v))
    for to in ["1e308,1,0", "1e5,1,0", "11,1,0", "0,1e308,0", "-1e308,1.2,0.4", "0,1,10.5", "0,1,1e-300"]:
        items += [("relocate", "cli", to), ("relocate", "py", to)]
    for h in ["1.2", "1.8", "0.5", "3"]:
        items += [("person-height", "cli", h), ("person-height", "py", h)]
    for kind in ["dangling", "dangling-slash", "link-dir", "file", "dangling-py", "loop", "parent-missing"]:
        items.append(("out-dir", kind, None))
    items += [("clip-path", "py", None), ("progress-ki", "py", None), ("progress-value-error", "py", None),
              ("progress-models", "py", "sc"), ("progress-models", "py", "se"), ("progress-models", "py", "sd")]
    rng.shuffle(items)
    while len(items) < n:
        items.append(rng.choice(items))
    items = items[:n]
    for what, where, v in items:
        def fn(ctx, what=what, where=where, v=v, rng=random.Random(rng.random())):
            c = ctx.dir
            clip = ds("p01/r09.bvh")
            if what == "budget":
                if where == "cli":
                    st = ctx.kin(["compare", clip, "--models", "sa", "--optimizers", "svd", "--budget", str(v), "--threads", "1",
                                  "-q", "-o", "R"], timeout=120)
                else:
                    st = ctx.py("_run(lambda: k.compare(%r, models=['sa'], optimizers=['svd'], budget=%d, threads=1) and None)" % (clip, v), timeout=120)
                if st.rc == 0 or (st.result or {}).get("ok"):
                    return
                ctx.refused(st, hints=["--budget", "budget"], what="a refusal of budget %d naming it" % v)
                return
            if what == "bvh-number":
                val, place = v
                w(os.path.join(c, "t.bvh"), bvh_with_value(clip, val, place))
                if where == "convert":
                    st = ctx.kin(["convert", "t.bvh", "-o", "o.bvh"])
                    outs = ["o.bvh"]
                elif where == "inspect":
                    st = ctx.kin(["inspect", "t.bvh"])
                    outs = []
                elif where == "segment-json":
                    st = ctx.kin(["segment", "t.bvh", "--json"])
                    outs = []
                elif where == "segment-manifest":
                    st = ctx.kin(["segment", "t.bvh", "-q", "--manifest", "s.csv"])
                    outs = ["s.csv"]
                elif where == "fit":
                    st = ctx.kin(["fit", "t.bvh", "--model", "sa", "--budget", "20", "--threads", "1", "-o", "o.json"])
                    outs = ["o.json"]
                else:
                    st = ctx.py("_run(lambda: k.read_bvh('t.bvh').to_bvh())")
                    outs = []
                if st.rc == 0 or (st.result or {}).get("ok"):
                    texts = [(o, open(os.path.join(c, o), encoding="latin-1").read()) for o in outs if os.path.exists(os.path.join(c, o))]
                    if st.kind == "py":
                        texts.append(("to_bvh()", str((st.result or {}).get("value"))))
                    texts.append(("stdout", st.text_out))
                    for o, t in texts:
                        ln = long_number(t)
                        if ln:
                            ctx.find("wrong_exit0", "%s prints %s" % (o, ln), st)
                            break
                        if nonfinite(t):
                            ctx.find("wrong_exit0", "%s: %s (from a value %s)" % (o, nonfinite(t), val), st)
                            break
                    return
                ctx.refused(st, hints=["t.bvh"], codes=(2,) if st.kind == "kin" else (2,), what="a refusal of a value %s" % val)
                return
            if what == "params-number":
                doc = json.load(open(os.path.join(FIX, "p_sa.json")))
                key = sorted(doc["values"])[0]
                text = json.dumps(doc, indent=2).replace('"%s": %s' % (key, json.dumps(doc["values"][key])), '"%s": %s' % (key, v), 1)
                w(os.path.join(c, "P.json"), text)
                if where == "synthesize":
                    st = ctx.kin(["synthesize", clip, "--params", "P.json", "--json", "-o", "s.bvh"])
                elif where == "reach":
                    st = ctx.kin(["reach", "--target", "0.3,1.1,0.4", "--params", "P.json", "--json", "-o", "r.bvh"])
                else:
                    st = ctx.py("_run(lambda: k.Params.load('P.json').to_json())")
                if st.rc == 0 or (st.result or {}).get("ok"):
                    t = str((st.result or {}).get("value")) if st.kind == "py" else st.text_out
                    ln = long_number(t)
                    if ln:
                        ctx.find("wrong_exit0", "the output prints %s" % ln, st)
                    return
                if st.kind == "kin" and st.rc == 1:
                    return  # a synthesis that did not reach with such values
                ctx.refused(st, hints=["P.json", key], what="a refusal of a parameter %s" % v)
                return
            if what == "with_values-number":
                st = ctx.py("c = k.read_bvh(%r)\nvv = c.values.copy(); vv[:, 5] = %s\n_run(lambda: c.with_values(vv).to_bvh())" % (clip, v))
                if ctx.succeeded(st, what="with_values of %s" % v):
                    ln = long_number(str(st.result.get("value")))
                    if ln:
                        ctx.find("wrong_exit0", "to_bvh prints %s" % ln, st)
                return
            if what == "relocate":
                far = max(abs(float(x)) for x in v.split(",")) > 10
                if where == "cli":
                    st = ctx.kin(["plan", "--scene", os.path.join(BOOKSHELF, "scene.json"), "--task", "relocate", "--object",
                                  "blue_book", "--to", v, "--budget-ms", "300", "-o", "p.bvh"], timeout=120)
                else:
                    st = ctx.py("_run(lambda: k.plan(%r, task='relocate', object='blue_book', to=[%s], budget_ms=300).frame_count)" % (
                        os.path.join(BOOKSHELF, "scene.json"), v), timeout=120)
                if far:
                    ctx.refused(st, hints=["10 m"], what="a refusal of a destination beyond 10 m")
                elif not (st.rc == 0 or (st.result or {}).get("ok")):
                    if st.kind == "kin" and st.rc == 1:
                        ctx.clean = True
                    else:
                        ctx.refused(st, hints=["--to", "to", "floor", "reach", "intersect", "beyond"], codes=(1, 2),
                                    what="a refusal of --to %s" % v)
                return
            if what == "person-height":
                if where == "cli":
                    st = ctx.kin(["reach", "--target", "0.3,1.1,0.4", "--person", clip, "--height", v, "--json", "-o", "r.bvh"])
                    if st.rc == 0:
                        if "height" not in st.text_err.lower():
                            ctx.find("wrong_exit0", "--height %s ignored with --person, silently" % v, st)
                    else:
                        ctx.refused(st, hints=["--height", "height"], codes=(2,), what="a refusal of --height with --person")
                else:
                    st = ctx.py("_run(lambda: k.reach([0.3, 1.1, 0.4], person=%r, height=%s).frame_count)" % (clip, v))
                    r = st.result or {}
                    if r.get("ok"):
                        if not any("height" in x.lower() for x in r.get("warnings") or []):
                            ctx.find("wrong_exit0", "height=%s ignored with person=, silently" % v, st)
                    else:
                        ctx.refused(st, hints=["height"], what="a refusal of height with person")
                return
            if what == "out-dir":
                shutil.copytree(os.path.join(FIX, "lib3"), os.path.join(c, "LIB"))
                tgt = "dl"
                if where.startswith("dangling"):
                    os.symlink("nowhere", os.path.join(c, "dl"))
                elif where == "link-dir":
                    os.makedirs(os.path.join(c, "real"))
                    os.symlink("real", os.path.join(c, "dl"))
                elif where == "file":
                    w(os.path.join(c, "dl"), "a file\n")
                elif where == "loop":
                    os.symlink("dl", os.path.join(c, "dl"))
                elif where == "parent-missing":
                    tgt = "missing/dl"
                before = snap(os.path.join(c, "dl"))
                if where == "dangling-py":
                    st = ctx.py("_run(lambda: k.fit('LIB', per='clip', model='sa', budget=20, threads=1, out_dir='dl') and None)")
                else:
                    st = ctx.kin(["fit", "LIB"] + lib_args("sa", 20) + (["-o", tgt + "/"] if where == "dangling-slash" else ["--out-dir", tgt]))
                ok = st.rc == 0 or (st.result or {}).get("ok")
                if where == "link-dir":
                    if ctx.succeeded(st, what="--out-dir a link to a folder"):
                        if not os.path.exists(os.path.join(c, "real", "library.csv")):
                            ctx.find("wrong_exit0", "no library.csv in the linked folder", st)
                    return
                if ok and where in ("file", "loop", "parent-missing"):
                    ctx.find("wrong_exit0", "--out-dir %s accepted" % where, st)
                    return
                if ok:
                    return  # a dangling link followed to a new folder: fine
                msg = st.text_err if st.kind == "kin" else (st.result or {}).get("msg", "")
                if "os error 17" in msg or "File exists" in msg:
                    return  # INTERNAL already flags it
                ctx.refused(st, hints=[tgt, "dl", "--out-dir", "out_dir"], codes=(2,), what="a refusal of --out-dir %s" % where)
                return
            if what == "clip-path":
                st = ctx.py("c = k.read_bvh(%r)\n_run(lambda: [type(c.path).__name__, isinstance(c.path, pathlib.PurePath), str(c.path)])" % clip)
                if ctx.succeeded(st, what="Clip.path"):
                    val = st.result.get("value")
                    stub = open(os.path.join(REPO, "python", "kinergy", "_kinergy.pyi")).read()
                    says_path = re.search(r"def path\(self\) -> (pathlib\.Path|str)", stub)
                    if says_path and says_path.group(1) == "str" and val[1]:
                        ctx.find("wrong_exit0", "Clip.path is a %s where the stub says str" % val[0], st)
                    if says_path and says_path.group(1).startswith("pathlib") and not val[1]:
                        ctx.find("wrong_exit0", "Clip.path is a %s where the stub says pathlib.Path" % val[0], st)
                return
            if what in ("progress-ki", "progress-value-error"):
                exc = "KeyboardInterrupt" if what == "progress-ki" else "ValueError('stop here')"
                body = ("n = [0]\n"
                        "def cb(d):\n    n[0] += 1\n    if n[0] == 3:\n        raise %s\n"
                        "_run(lambda: k.fit(%r, model='sc', budget=200, threads=1, progress=cb).distances)") % (exc, clip)
                st = ctx.py(body)
                r = st.result or {}
                if r.get("ok"):
                    ctx.find("wrong_exit0", "the callback's exception was swallowed", st)
                    return
                want = "KeyboardInterrupt" if what == "progress-ki" else "ValueError"
                if r.get("exc") != want:
                    ctx.find("bad_message", "the callback's %s surfaced as %s" % (want, r.get("exc")), st)
                    return
                text = (r.get("msg") or "") + " ".join(r.get("notes") or []) + (r.get("cause") or "")
                if what == "progress-ki" and not text.strip():
                    ctx.find("bad_message", "KeyboardInterrupt from the callback has no message or note", st)
                    return
                ctx.clean = True
                return
            if what == "progress-models":
                body = ("seen = []\n"
                        "def cb(d):\n    seen.append((d.get('model'), d.get('iteration'), d.get('stage'), d.get('phase')))\n"
                        "_run(lambda: (k.fit(%r, model=%r, budget=16, threads=1, progress=cb).distances, seen))") % (clip, v)
                st = ctx.py(body, timeout=120)
                if not ctx.succeeded(st, what="fit with a progress callback"):
                    return
                dists, seen = st.result["value"]
                models = [s[0] for s in seen]
                order = ["sa", "sb", "sc", "sd", "se"]
                want = order[:order.index(v) + 1]
                if any(m not in order for m in models):
                    ctx.find("wrong_exit0", "progress reports models %s" % sorted(set(map(str, models))), st)
                elif [m for m in order if m in models] != want:
                    ctx.find("wrong_exit0", "progress reported models %s, the fit ran %s" % (
                        sorted(set(models), key=order.index), want), st)
                return
        cases.append(Case(fam, "%s %s %s" % (what, where, v if v is not None else ""), fn,
                          needs_py=(where.startswith("py") or what in ("clip-path", "progress-ki", "progress-value-error",
                                                                       "progress-models", "with_values-number"))))
    return cases


# ----------------------------------------------------------------------------- family 12

MOUNTS = []


def can_mount():
    p = os.path.join(SCR, "mount-probe")
    os.makedirs(p, exist_ok=True)
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", p], capture_output=True)
    if r.returncode != 0:
        return False
    subprocess.run(["umount", p], capture_output=True)
    return True


def mount_tmpfs(path, size, ro=False):
    os.makedirs(path, exist_ok=True)
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=%s" % size, "tmpfs", path], capture_output=True)
    if r.returncode != 0:
        return False
    MOUNTS.append(path)
    return True


def umount_all():
    while MOUNTS:
        p = MOUNTS.pop()
        subprocess.run(["umount", "-l", p], capture_output=True)


def fam_kills_fs(rng, n):
    fam = "12_kills_fs"
    cases = []
    mount_ok = can_mount()
    kinds = ["kill-resume"] * 4 + ["kill-shard-resume"] * 2 + ["kill-twice"] + \
        (["full", "full", "full-py", "readonly", "full-shards"] if mount_ok else []) + \
        ["shards-is-file", "library-csv-folder", "result-dir-unwritable-name"]
    for i in range(n):
        kind = kinds[i % len(kinds)]

        def fn(ctx, kind=kind, rng=random.Random(rng.random())):
            c = ctx.dir
            LIB = os.path.join(c, "LIB")
            make_lib(LIB, rng, rng.randint(4, 8), persons=["p01", "p02"])
            args = lib_args(rng.choice(["sb", "sc"]), rng.choice([40, 60]))
            if rng.random() < 0.3:
                args[args.index("--threads") + 1] = "2"
            if kind.startswith("kill"):
                N = 2 if kind == "kill-shard-resume" else 1
                sh = lambda s: (["--shard", "%d/%d" % (s, N)] if N > 1 else [])
                for s in range(1, N + 1):
                    ctx.kin(["fit", "LIB"] + args + ["--out-dir", "D"] + sh(s), sig=(signal.SIGKILL, rng.uniform(0.05, 1.5)))
                    if kind == "kill-twice":
                        ctx.kin(["fit", "LIB"] + args + ["--out-dir", "D", "--resume"], sig=(signal.SIGKILL, rng.uniform(0.05, 1.0)))
                    for r in library_results(os.path.join(c, "D")):
                        try:
                            json.load(open(os.path.join(c, "D", r)))
                        except Exception as e:
                            ctx.find("data_loss", "a killed run left a broken result %s: %r" % (r, e))
                    st = ctx.kin(["fit", "LIB"] + args + ["--out-dir", "D", "--resume"] + sh(s), timeout=300)
                    if not ctx.succeeded(st, what="--resume after kill -9"):
                        return
                st = ctx.kin(["collect", "D"])
                if ctx.succeeded(st, what="collect after kills and resumes"):
                    verify_library(ctx, os.path.join(c, "D"), LIB, args, st)
                return
            if kind in ("full", "full-py", "full-shards", "readonly"):
                mnt = os.path.join(c, "mnt")
                size = rng.choice(["12k", "24k", "40k", "64k", "100k"])
                if not mount_tmpfs(mnt, size):
                    ctx.find("bad_message", "the sweep could not mount a tmpfs")
                    return
                try:
                    if kind == "full-shards":
                        os.makedirs(os.path.join(mnt, "D", "shards"))
                        w(os.path.join(mnt, "filler"), b"x" * 1)
                    if kind == "readonly":
                        subprocess.run(["mount", "-o", "remount,ro", mnt], capture_output=True)
                    if kind == "full-py":
                        st = ctx.py("_run(lambda: k.fit('LIB', per='clip', model=%r, budget=%s, threads=1, out_dir='mnt/D') and None)" % (
                            args[args.index("--model") + 1], args[args.index("--budget") + 1]), timeout=300)
                    else:
                        st = ctx.kin(["fit", "LIB"] + args + ["--out-dir", "mnt/D"], timeout=300)
                    ok = st.rc == 0 or (st.result or {}).get("ok")
                    if ok:
                        st2 = ctx.kin(["collect", "mnt/D"])
                        if st2.rc == 0:
                            verify_library(ctx, os.path.join(mnt, "D"), LIB, args, st2)
                        return
                    msg = st.text_err if st.kind == "kin" else (st.result or {}).get("msg", "")
                    ctx.refused(st, hints=["space", "read-only", "Read-only", "mnt/D", "mnt"], codes=(1, 2),
                                what="a clear failure on a %s file system" % kind)
                    for r in library_results(os.path.join(mnt, "D")):
                        try:
                            json.load(open(os.path.join(mnt, "D", r)))
                        except Exception as e:
                            ctx.find("data_loss", "a full disk left a broken result %s: %r" % (r, e), st)
                            break
                    if os.path.isdir(os.path.join(mnt, "D")):
                        st2 = ctx.kin(["collect", "mnt/D"])
                        if st2.rc == 0:
                            verify_library(ctx, os.path.join(mnt, "D"), LIB, args, st2)
                finally:
                    subprocess.run(["umount", "-l", mnt], capture_output=True)
                    if mnt in MOUNTS:
                        MOUNTS.remove(mnt)
                return
            if kind == "shards-is-file":
                w(os.path.join(c, "D", "shards"), "not a folder\n")
                st = ctx.kin(["fit", "LIB"] + args + ["--out-dir", "D"])
                ctx.refused(st, hints=["shards"], codes=(1, 2), what="a refusal of D/shards as a file")
                if snap(os.path.join(c, "D", "shards")) != ("file", sha(b"not a folder\n")):
                    ctx.find("data_loss", "D/shards (a file) was replaced", st)
                return
            if kind == "library-csv-folder":
                os.makedirs(os.path.join(c, "D", "library.csv", "inside"))
                w(os.path.join(c, "D", "library.csv", "inside", "keep"), "keep\n")
                st = ctx.kin(["fit", "LIB"] + args + ["--out-dir", "D"])
                ctx.refused(st, hints=["library.csv"], codes=(1, 2), what="a refusal of D/library.csv as a folder")
                if not os.path.exists(os.path.join(c, "D", "library.csv", "inside", "keep")):
                    ctx.find("data_loss", "D/library.csv (a folder) was removed", st)
                return
            if kind == "result-dir-unwritable-name":
                # a result's folder exists as a file: p01 in D is a file
                w(os.path.join(c, "D", "p01"), "a file named like a person folder\n")
                st = ctx.kin(["fit", "LIB"] + args + ["--out-dir", "D"])
                both = os.path.isdir(os.path.join(LIB, "p01")) and os.path.isdir(os.path.join(LIB, "p02"))
                if st.rc == 0 and both:
                    ctx.find("wrong_exit0", "exit 0 though D/p01 is a file", st)
                elif st.rc == 0:
                    return  # the takes' root is one person's folder: D/p01 is in nobody's way
                else:
                    ctx.refused(st, hints=["p01"], codes=(1, 2), what="a refusal naming D/p01")
                if snap(os.path.join(c, "D", "p01"))[0] != "file":
                    ctx.find("data_loss", "D/p01 (a file) was replaced", st)
        cases.append(Case(fam, kind, fn))
    return cases


# ----------------------------------------------------------------------------- main

FAMILIES = [
    ("00_outputs", fam_outputs, 84, 14),
    ("01_names", fam_names, 120, 12),
    ("02_take_edits", fam_take_edits, 220, 24),
    ("03_settings", fam_settings, 110, 16),
    ("04_resume", fam_resume, 90, 10),
    ("05_links", fam_links, 84, 12),
    ("06_bounds", fam_bounds, 220, 30),
    ("07_sigint", fam_sigint, 45, 8),
    ("08_py_strict", fam_py_strict, 230, 30),
    ("09_tables", fam_tables, 90, 16),
    ("10_options", fam_options, 70, 12),
    ("11_messages", fam_messages, 190, 24),
    ("12_kills_fs", fam_kills_fs, 45, 10),
]


def main():
    global K, PY, SCR, FIX, QUICK
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--kinergy", default=DEFAULT_KINERGY)
    ap.add_argument("--python", default=DEFAULT_PYTHON, help="an interpreter that imports kinergy")
    ap.add_argument("--no-python", action="store_true", help="skip the cases that need the Python package")
    ap.add_argument("--quick", action="store_true", help="fewer cases per family (a smoke run)")
    ap.add_argument("--only", default="", help="comma-separated family names or numbers")
    ap.add_argument("--scratch", default="/tmp/kinergy-library-sweep")
    ap.add_argument("--keep", action="store_true", help="keep the folders of ok and clean_error cases too")
    ap.add_argument("--seed", type=int, default=42)
    ap.add_argument("--summary", default="/tmp/library-sweep-summary.txt")
    ap.add_argument("--report", default="/tmp/library-sweep-report.txt")
    ap.add_argument("--cases", default="/tmp/library-sweep-cases.jsonl")
    a = ap.parse_args()
    K = os.path.abspath(a.kinergy)
    QUICK = a.quick
    if not os.access(K, os.X_OK):
        sys.exit("no kinergy binary at %s (cargo build --release -p kinergy-cli)" % K)
    PY = None
    py_note = "skipped (--no-python)"
    if not a.no_python:
        r = subprocess.run([a.python, "-c", "import kinergy, sys; sys.stdout.write(kinergy.__file__)"],
                           capture_output=True, timeout=60) if os.access(a.python, os.X_OK) else None
        if r is not None and r.returncode == 0:
            PY = a.python
            py_note = "%s (kinergy from %s)" % (PY, r.stdout.decode())
        else:
            py_note = "skipped: %s cannot import kinergy" % a.python
    SCR = os.path.abspath(a.scratch)
    if not SCR.startswith("/tmp/"):
        sys.exit("--scratch must be under /tmp")
    if os.path.exists(SCR):
        subprocess.run(["sh", "-c", "grep ' %s/' /proc/mounts | cut -d' ' -f2 | xargs -r -n1 umount -l" % SCR],
                       capture_output=True)
        shutil.rmtree(SCR)
    os.makedirs(SCR)
    FIX = os.path.join(SCR, "fix")
    t_start = time.monotonic()
    repo_before = {p: snap(p) for p in (DATA, BOOKSHELF) + ((SHARED,) if os.path.isdir(SHARED) else ())}
    prepare_fixtures()
    fix_before = snap(os.path.join(FIX, "ds"))
    only = [x.strip() for x in a.only.split(",") if x.strip()]
    results = []
    report = open(a.report, "w")
    report.write("kinergy library sweep: cases neither ok nor clean_error (binary %s, seed %d%s)\n"
                 "Python: %s\n\n" % (K, a.seed, ", quick" if a.quick else "", py_note))
    jl = open(a.cases, "w")
    skipped_py = 0
    try:
        for name, gen, full, quick in FAMILIES:
            if only and not any(name == o or name.split("_")[0] == o.zfill(2) for o in only):
                continue
            rng = random.Random("%d:%s" % (a.seed, name))
            cases = gen(rng, quick if a.quick else full)
            t_fam = time.monotonic()
            print("== %s: %d cases" % (name, len(cases)), flush=True)
            for k_, case in enumerate(cases):
                if case.needs_py and PY is None:
                    skipped_py += 1
                    continue
                cdir = os.path.join(SCR, "cases", name, "%04d" % (k_ + 1))
                os.makedirs(cdir)
                ctx = Ctx(case, cdir)
                t0 = time.monotonic()
                try:
                    case.fn(ctx)
                except Exception as e:  # a bug of the sweep must not end it
                    import traceback
                    ctx.find("bad_message", "sweep error: %r %s" % (e, traceback.format_exc()[-400:]))
                finally:
                    umount_all()
                cls = ctx.worst()
                results.append((name, cls))
                rec = {"family": name, "label": case.label, "class": cls, "findings": ctx.findings,
                       "wall_s": round(time.monotonic() - t0, 2),
                       "steps": [{"cmd": s.command(), "exit": s.rc, "wall_s": round(s.wall, 2), "stop_s": s.stop,
                                  "stderr_head": s.err[:300].decode("utf-8", "replace"),
                                  "result": s.result} for s in ctx.steps]}
                jl.write(json.dumps(rec, default=str) + "\n")
                jl.flush()
                if cls in BAD:
                    report.write("[%s] %s #%d: %s\n" % (cls, name, k_ + 1, case.label))
                    for fc, fd in ctx.findings:
                        report.write("    - %s: %s\n" % (fc, fd))
                    for j, s in enumerate(ctx.steps):
                        report.write("    %d. $ %s\n" % (j + 1, s.command()))
                        extra = ""
                        if s.kind == "py":
                            r = s.result or {}
                            extra = " -> %s" % (("returned %.200r" % (r.get("value"),)) if r.get("ok") else
                                                "%s: %.300s" % (r.get("exc"), r.get("msg")))
                            if s.argv and os.path.exists(s.argv[0]):
                                body = open(s.argv[0]).read().split(PRELUDE, 1)[-1].strip()
                                report.write("       python: %s\n" % body.replace("\n", "\n               ")[:600])
                        report.write("       exit %s, %.2fs%s, stderr %d bytes: %.300r%s\n" % (
                            s.rc, s.wall, (", stopped %.1fs after the signal" % s.stop) if s.stop is not None else "",
                            len(s.err), s.err[:300], extra))
                    report.write("\n")
                    report.flush()
                elif not a.keep:
                    shutil.rmtree(cdir, ignore_errors=True)
            counts = {}
            for fam_, cls in results:
                if fam_ == name:
                    counts[cls] = counts.get(cls, 0) + 1
            print("   %s  (%.0fs)" % (", ".join("%s %d" % (c_, counts[c_]) for c_ in CLASSES if c_ in counts),
                                     time.monotonic() - t_fam), flush=True)
    finally:
        umount_all()
    glob_findings = []
    for p, s in repo_before.items():
        if snap(p) != s:
            glob_findings.append("repository data changed: %s" % p)
    if snap(os.path.join(FIX, "ds")) != fix_before:
        glob_findings.append("shared fixture takes changed: %s" % os.path.join(FIX, "ds"))
    jl.close()
    fams = [f[0] for f in FAMILIES if any(r[0] == f[0] for r in results)]
    lines = []
    hdr = "%-15s %6s " % ("family", "cases") + " ".join("%11s" % c_ for c_ in CLASSES)
    lines.append("kinergy library sweep (seed %d%s), %s, %.0f s" % (a.seed, ", quick" if a.quick else "", K,
                                                                  time.monotonic() - t_start))
    lines.append("Python cases: %s%s" % (py_note, ("; %d cases skipped" % skipped_py) if skipped_py else ""))
    lines.append("")
    lines.append(hdr)
    lines.append("-" * len(hdr))
    tot = {c_: 0 for c_ in CLASSES}
    for fam_ in fams:
        rs = [r for r in results if r[0] == fam_]
        row = "%-15s %6d " % (fam_, len(rs))
        for c_ in CLASSES:
            k_ = sum(1 for r in rs if r[1] == c_)
            tot[c_] += k_
            row += "%11s " % (k_ if k_ else ".")
        lines.append(row.rstrip())
    lines.append("-" * len(hdr))
    lines.append(("%-15s %6d " % ("total", len(results)) + " ".join("%11s" % (tot[c_] if tot[c_] else ".")
                                                                   for c_ in CLASSES)).rstrip())
    lines.append("")
    lines.append("details of every case neither ok nor clean_error: %s; every case: %s" % (a.report, a.cases))
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
    sys.exit(0 if all(r[1] in ("ok", "clean_error") for r in results) and not glob_findings else 1)


if __name__ == "__main__":
    main()
