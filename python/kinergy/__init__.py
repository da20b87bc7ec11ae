"""Kinergy from Python: learn how a person reaches from BVH motion capture and synthesize
reaches in their style.

The Rust toolkit behind the ``kinergy`` command, with numpy arrays in and out::

    import kinergy
    clip = kinergy.read_bvh("take.bvh")                  # unit, up axis: guessed
    clip.positions.shape                                 # (frames, joints, 3), meters, Y up
    kinergy.segment(clip, arm="right")                   # reach / return / other segments
    p = kinergy.fit(["me/"], model="sd", per="person")   # one vector for a person
    p.save("me.json")                                    # the file `kinergy fit` writes
    motion = kinergy.synthesize(clip, p, frames="auto")  # the reach, in their style
    body = kinergy.reach([-0.3, 1.3, 0.45], params=p)    # the full-body character reaches
    moved, report = kinergy.retarget(clip, kinergy.read_bvh("rig.bvh"))  # onto another body
    kinergy.view([clip, motion], "view.html")            # both in a browser, offline

Every function does what the CLI command of the same name does, with the same defaults and
the same results for the same seed. Errors are exceptions below :class:`KinergyError`.
"""

from __future__ import annotations

from . import _kinergy
from ._kinergy import (
    BvhError,
    Clip,
    InputError,
    KinergyError,
    NothingToFitError,
    Params,
    ParamsError,
    UnreachableError,
    collect,
    fit,
    from_positions,
    hand_speed,
    plan,
    reach,
    read_bvh,
    retarget,
    segment,
    style,
    synthesize,
    view,
)

__version__: str = _kinergy.__version__

__all__ = [
    "BvhError",
    "Clip",
    "InputError",
    "KinergyError",
    "NothingToFitError",
    "Params",
    "ParamsError",
    "UnreachableError",
    "collect",
    "compare",
    "fit",
    "from_positions",
    "hand_speed",
    "plan",
    "reach",
    "read_bvh",
    "retarget",
    "segment",
    "style",
    "synthesize",
    "view",
]


def compare(clips=None, *, as_records: bool = False, **options):
    """The paper's experiments on captures, as ``kinergy compare`` runs them: per reach, the
    models fitted nested (Fig. 3), S_A and S_C with each optimizer (Fig. 4), with
    ``baselines`` S_C from neutral, Nelder–Mead and particle swarm, then the parameter field's
    leave-one-out rows.

    Returns one dict per fit with the columns of the CLI's ``results.csv`` (clip, arm, onset,
    end, model, optimizer, method, distance_m, frames, evaluations, seconds), or a numpy
    record array with ``as_records=True``. Keyword arguments: models, optimizers, optimizer,
    baselines, seed, budget, threads, progress (called with (done, total) as each reach
    ends), arm, select, frames, segments, unit, … (see ``kinergy._kinergy.compare``).
    """
    rows = _kinergy.compare(clips, **options)
    if not as_records:
        return rows
    import numpy as np

    names = list(_kinergy.RESULTS_COLUMNS)
    return np.rec.fromrecords([tuple(r[n] for n in names) for r in rows], names=names)
