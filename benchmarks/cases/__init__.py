"""The registered benchmark cases: one module per method, gathered here in a fixed order.

Adding cases for a method: write ``benchmarks/cases/<method>.py`` with a ``CASES`` list and add it
to the import below.
"""

from __future__ import annotations

from . import affine, fast, nfpt, quilt
from .base import Case, Input

CASES: list[Case] = [*quilt.CASES, *fast.CASES, *nfpt.CASES, *affine.CASES]


def by_name() -> dict[str, Case]:
    return {c.name: c for c in CASES}


__all__ = ["CASES", "Case", "Input", "by_name"]
