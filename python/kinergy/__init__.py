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
    Params,
    ParamsError,
    UnreachableError,
    fit,
    hand_speed,
    plan,
    reach,
    read_bvh,
    segment,
    style,
    synthesize,
)

__version__: str = _kinergy.__version__

__all__ = [
    "BvhError",
    "Clip",
    "InputError",
    "KinergyError",
    "Params",
    "ParamsError",
    "UnreachableError",
    "compare",
    "fit",
    "hand_speed",
    "plan",
    "reach",
    "read_bvh",
    "segment",
    "style",
    "synthesize",
]


def compare(
    clips,
    *,
    models=("sa", "sb", "sc", "sd"),
    optimizer: str = "svd",
    seed: int = 1,
    budget: int | None = None,
    threads: int | None = None,
    as_records: bool = False,
    **options,
):
    """The paper's Fig. 3 experiment on ``clips``: each reach fitted on its own (per clip),
    the models nested poorest first; one row per reach and model with its distance.

    Returns a list of dicts (``clip``, ``frames``, ``arm``, ``model``, ``optimizer``,
    ``distance_m``, ``evaluations``), or a numpy record array with ``as_records=True``.
    Further keyword arguments go to :func:`fit` (arm, select, unit, …).
    """
    richest = max(models)
    fits = fit(
        clips,
        model=richest,
        optimizer=optimizer,
        per="clip",
        seed=seed,
        budget=budget,
        threads=threads,
        **options,
    )
    rows = []
    for params in fits:
        record = params.record
        reach = record["reaches"][0]
        arm = (reach.get("arm") or {}).get("side")
        for stage in record.get("nested") or []:
            if stage["model"] not in models:
                continue
            rows.append(
                {
                    "clip": reach["clip"],
                    "frames": tuple(reach["frames"]),
                    "arm": arm,
                    "model": stage["model"],
                    "optimizer": optimizer,
                    "distance_m": stage["score_m"],
                    "evaluations": stage["evaluations"],
                }
            )
    if not as_records:
        return rows
    import numpy as np

    return np.rec.fromrecords(
        [
            (r["clip"], r["frames"][0], r["frames"][1], r["arm"] or "", r["model"], r["optimizer"],
             r["distance_m"], r["evaluations"])
            for r in rows
        ],
        names="clip,onset,end,arm,model,optimizer,distance_m,evaluations",
    )
