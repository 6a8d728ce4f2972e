"""Which engine runs a quilting pass's per-block steps: the numba kernels of
``weft.core._kernels.quilting`` and ``weft.core._kernels.seams``, or their numpy copies
(:mod:`weft.core.quilting.numpy_kernels`); the selection rule of the pass, and the seam rule.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import codes as _K  # the kernel's array codes, without importing numba (a test checks it)
from . import numpy_kernels as _nk
from .pass_options import _Pass

# Below this many blocks a synthesis without Poisson runs the per-block step in numpy when numba
# is not loaded yet: numba's one-time start-up (import, registries, kernel cache) costs more than
# the numpy steps of that many blocks. Both engines give the same pixels.
NUMPY_ENGINE_MAX_BLOCKS = 1024


@dataclass(frozen=True)
class _Steps:
    """The per-block steps of one engine, the numba kernels or their numpy copies, called alike.

    ``choose`` is the pass's selection rule, ``(cross, sq, const, cost, u, seed) -> position``;
    ``blend`` (the Poisson band) and the seam rule's kernels are None in the numpy engine.
    """

    place: Callable[..., Any]
    template: Callable[..., Any]
    blend: Callable[..., Any] | None
    error: Callable[..., Any]
    cut: Callable[..., Any]
    choose: Callable[..., Any]
    by_seam: Callable[..., Any]
    best_k: Callable[..., Any] | None
    seam_error: Callable[..., Any] | None
    seam_cut: Callable[..., Any] | None
    block_error: Callable[..., Any] | None


def _uses_numpy(p: _Pass, synthesis: bool, blocks: int) -> bool:
    """Whether the pass runs the numpy engine: asked for, or a small synthesis without Poisson while
    numba is not loaded yet."""
    import sys

    return (
        p.engine == "numpy"
        or p.engine == "auto"
        and not p.poisson
        and synthesis
        and blocks <= NUMPY_ENGINE_MAX_BLOCKS
        and "weft.core._kernels.quilting" not in sys.modules
    )


def _rule(p: _Pass, by_best, by_tol, by_eps, by_sampled) -> Callable[..., Any]:
    """The pass's selection rule, one kernel per rule (a run compiles only the one it uses); every
    rule takes (cross, sq, const, cost, u, seed)."""
    if p.rule == "sampled":
        return by_sampled
    if p.rule == "epsilon":
        return lambda cross, sq, const, cost, u, seed: by_eps(cross, sq, const, cost, p.epsilon, u)
    if p.tol > 1:
        return lambda cross, sq, const, cost, u, seed: by_tol(cross, sq, const, cost, p.tol, u)
    return lambda cross, sq, const, cost, u, seed: by_best(cross, sq, const, cost)


def _steps(p: _Pass, use_numpy: bool) -> _Steps:
    """The steps of the numpy engine, or the numba kernels (numba loads here, on first use)."""
    if use_numpy:
        choose = _rule(
            p, _nk._choose_best_numpy, _nk._choose_tol_numpy, _nk._choose_epsilon_numpy, _nk._choose_sampled_numpy
        )
        return _Steps(
            place=_nk._place_block_numpy,
            template=_nk._make_template_numpy,
            blend=None,
            error=_nk._block_error_numpy,
            cut=_nk._cut_mask_into_numpy,
            choose=choose,
            by_seam=_nk._by_seam_numpy,
            best_k=None,
            seam_error=None,
            seam_cut=None,
            block_error=None,
        )
    from .._kernels import quilting as _k  # numba loads on first use, not with the CLI
    from .._kernels import seams as _seams

    return _Steps(
        place=_k.place_block,
        template=_k.make_template,
        blend=_k.poisson_band,
        error=_k.block_error,
        cut=_seams.cut_mask,
        choose=_rule(p, _k.choose_best, _k.choose_tol, _k.choose_epsilon, _k.choose_sampled),
        by_seam=_by_seam,
        best_k=_k.best_k,
        seam_error=_k.seam_error,
        seam_cut=_seams.cut_mask,
        block_error=_k.block_error,
    )


def _by_seam(
    cross,
    sq,
    const,
    cost_buf,
    pool,
    candidates,
    canvas,
    filled,
    tex,
    ip,
    err,
    mask,
    best_k,
    block_error,
    cut,
    seam_error,
    pw,
) -> int:
    """The seam rule: of the ``pool`` lowest-cost positions (the tol rule's candidates), the one
    whose minimum-error cut runs through the least error (``seam_error``; ties: the earlier
    candidate). The overlap SSD ranks a block by its whole overlap, but what shows is the error
    along the cut, so cutting several candidates breaks fewer structures (mortar joints) at the
    seams. The winner's cut is left in ``mask`` (the caller pastes with it)."""
    n = int(best_k(cross, sq, const, cost_buf, pool, candidates))
    best, best_err = int(candidates[0]), np.inf
    best_mask = np.empty_like(mask)
    for c in candidates[:n]:
        ip[_K.P_SY], ip[_K.P_SX] = divmod(int(c), pw)
        block_error(canvas, filled, tex, ip, err)
        cut(err, int(ip[_K.P_TOP]), int(ip[_K.P_LEFT]), int(ip[_K.P_RIGHT]), int(ip[_K.P_BOTTOM]), mask)
        e = float(seam_error(err, mask))
        if e < best_err:
            best, best_err = int(c), e
            best_mask[...] = mask
    mask[...] = best_mask
    return best
