"""weft's benchmark harness: ``python -m benchmarks [--quick] [CASE...]``.

Cases live in :mod:`benchmarks.cases` (each: a method, inputs made from the bundled examples,
parameters, which quality figures to compute, an optional G'MIC counterpart). See
:mod:`benchmarks.harness` for how they are timed.
"""
