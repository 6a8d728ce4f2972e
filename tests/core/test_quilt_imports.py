"""A small quilting synthesis runs its numpy engine without loading numba or scipy.sparse: their
imports (~0.15 s and ~0.1 s) were most of the gap between ``weft quilt`` and G'MIC's whole process
(``quilt-mincut-512``)."""

import subprocess
import sys

import pytest

SCRIPT = """
import sys
import numpy as np
from weft.core.quilting import METHOD, QuiltParams
tex = np.random.default_rng(0).random((64, 64)).astype(np.float32)
res = METHOD.run({"texture": tex}, QuiltParams(size=(128, 128), block=16), rng=1)
assert res.image.shape == (128, 128), res.image.shape
assert 0.0 < res.figures["verbatim_fraction"] <= 1.0, res.figures
print(" ".join(m for m in ("numba", "scipy.sparse", "weft.core._kernels") if m in sys.modules) or "none")
"""


@pytest.mark.slow
def test_small_synthesis_loads_neither_numba_nor_scipy_sparse():
    out = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "none"


@pytest.mark.slow
def test_the_command_line_loads_no_scipy_fft_until_a_method_needs_it():
    """``weft`` imports every method's module (the registry); affine's spectral code imported
    scipy.fft at the top, 0.12 s of every process's start (``weft fill``, ``weft quilt``...)."""
    script = (
        "import sys; from weft.core import registry; assert 'affine' in registry.methods(); "
        "print('scipy.fft' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "False"
