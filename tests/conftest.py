import os

# The GUI tests run without a screen unless one is asked for explicitly.
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
