#!/usr/bin/env bash
# Make a separate Python environment holding the fill suite's PyPI peers (pypatchmatch, resynthesizer),
# which are never weft's dependencies, and print the line that points the benchmarks at it.
#   bash benchmarks/peers_env.sh [DIR]      (DIR default: /tmp/weft-peers)
#   export WEFT_PEERS_PYTHON=DIR/bin/python; python -m benchmarks.fill_suite
# G'MIC comes from Debian (apt-get install gmic); OpenCV's shift-map runs in weft's own environment.
set -euo pipefail
dir="${1:-/tmp/weft-peers}"
python3 -m venv "$dir"
"$dir/bin/pip" install -q pypatchmatch resynthesizer pillow numpy opencv-python-headless
for module in patchmatch resynthesizer; do
    if "$dir/bin/python" -c "import $module" 2>/dev/null; then
        echo "$module: ok"
    else
        echo "$module: does not import in $dir (its row will say so)" >&2
    fi
done
echo "export WEFT_PEERS_PYTHON=$dir/bin/python"
