#!/usr/bin/env sh
# Benchmark-only dependencies of bench/compare_gl.py: Mesa's llvmpipe behind EGL (system packages) and moderngl
# (into the Python environment that runs the benchmark). The lanevil packages never import either.
#
# Usage, from the repository root: sh bench/setup_gl.sh [PYTHON]   (PYTHON defaults to .venv/bin/python)
set -eu

PYTHON=${1:-.venv/bin/python}
GL_PACKAGES="libegl1 libegl-mesa0 libgl1-mesa-dri libgles2"

missing=""
for package in $GL_PACKAGES; do
    dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "ok installed" || missing="$missing $package"
done
if [ -n "$missing" ]; then
    SUDO=""
    [ "$(id -u)" -eq 0 ] || SUDO=sudo
    $SUDO apt-get update
    # shellcheck disable=SC2086  # one word per package
    $SUDO apt-get install -y --no-install-recommends $missing
fi

"$PYTHON" -m pip install --quiet moderngl
"$PYTHON" - <<'PY'
import moderngl

ctx = moderngl.create_context(standalone=True, backend="egl")
print("moderngl", moderngl.__version__, "on", ctx.info["GL_RENDERER"])
PY
