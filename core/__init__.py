"""weft core: algorithms, image I/O, parameters, jobs and metrics.

Never imports Qt or ``app`` (a test checks this), so every method runs headless.
"""

__version__ = "0.1.0"
