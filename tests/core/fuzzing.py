"""What the fuzz tests (``test_fuzz_*.py``) share: hypothesis settings, warnings as errors, and the
checks (an output is a finite float32 image in [0, 1] of the documented shape; a refusal
is one line naming what is wrong)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, settings
from weft.core.errors import InvalidParameter, WeftError

# Per example: generous enough for the first example to compile numba kernels in a fresh clone
# (cold cache), still a bound that turns a hang into a failure.
COLD_DEADLINE_MS = 60_000

#: ``pytestmark`` of every fuzz module: a NumPy RuntimeWarning would print extra lines on stderr,
#: breaking the one-line promise, so it fails the test.
RUNTIME_WARNINGS_ARE_ERRORS = pytest.mark.filterwarnings("error::RuntimeWarning")


def fuzz(examples: int) -> settings:
    """Hypothesis settings: ``examples`` examples, each within :data:`COLD_DEADLINE_MS`."""
    return settings(max_examples=examples, deadline=COLD_DEADLINE_MS, suppress_health_check=[HealthCheck.too_slow])


def one_line_naming(error: WeftError, names) -> None:
    """``error`` is one non-empty line naming one of ``names`` (and its parameter, if it has one)."""
    message = str(error)
    assert "\n" not in message, message
    assert message.strip(), "empty message"
    assert any(n in message for n in names), f"{message!r} names none of {sorted(names)}"
    if isinstance(error, InvalidParameter) and error.name is not None:
        assert error.name in message, message


def check_image(out, hw, channels: int | None) -> None:
    """``out`` is a finite float32 image in [0, 1] of height and width ``hw``; ``channels`` 1 (2-D),
    3 (H, W, 3) or ``None`` (either)."""
    assert isinstance(out, np.ndarray) and out.dtype == np.float32
    assert out.shape[:2] == tuple(hw), (out.shape, hw)
    if channels is not None:
        assert out.shape[2:] == ((3,) if channels == 3 else ()), out.shape
    assert np.isfinite(out).all()
    assert out.min() >= 0.0 and out.max() <= 1.0
