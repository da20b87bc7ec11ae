from __future__ import annotations

from typing import Any, Sequence

import numpy as np
import numpy.typing as npt

from ._kinergy import (
    BvhError as BvhError,
    Clip as Clip,
    ClipLike,
    InputError as InputError,
    KinergyError as KinergyError,
    NothingToFitError as NothingToFitError,
    Params as Params,
    ParamsError as ParamsError,
    UnreachableError as UnreachableError,
    collect as collect,
    fit as fit,
    from_positions as from_positions,
    hand_speed as hand_speed,
    plan as plan,
    reach as reach,
    read_bvh as read_bvh,
    retarget as retarget,
    segment as segment,
    style as style,
    synthesize as synthesize,
    view as view,
)

__version__: str

def compare(
    clips: ClipLike | Sequence[ClipLike] | None = None,
    *,
    as_records: bool = False,
    **options: Any,
) -> list[dict[str, Any]] | np.recarray:
    """The paper's experiments, as `kinergy compare` runs them: results.csv's rows."""
