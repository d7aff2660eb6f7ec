#!/usr/bin/env bash
# Peer-engine benchmark for the thesis rattle box case C (MuJoCo, and Drake where it installs).
# Usage: bench/peers/run_peers.sh [rattle_box_peers.py options, e.g. --window 5 --drake-steps 1e-4]
# stdout: one JSON object per engine/setting; stderr: progress and install messages.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
venv="$here/.venv"
py="${PYTHON:-python3}"
if [ ! -x "$venv/bin/python" ]; then
  "$py" -m venv "$venv" >&2
  "$venv/bin/pip" install -q --upgrade pip >&2
fi
if ! "$venv/bin/python" -c "import mujoco" 2>/dev/null; then
  "$venv/bin/pip" install -q "mujoco>=4,<5" >&2
fi
# `--drake-steps none` (or '') skips Drake: nothing to install.
want_drake=1
prev=""
for a in "$@"; do
  if [ "$prev" = "--drake-steps" ] && { [ -z "$a" ] || [ "$a" = "none" ] || [ "$a" = "''" ]; }; then
    want_drake=0
  fi
  prev="$a"
done
if [ "$want_drake" = 1 ] && ! "$venv/bin/python" -c "import pydrake.multibody.plant" 2>/dev/null; then
  if ! "$venv/bin/pip" install -q drake >&2; then
    echo "run_peers: drake did not install; its row will say unavailable" >&2
  elif ! "$venv/bin/python" -c "import pydrake.multibody.plant" 2>/dev/null; then
    echo "run_peers: drake installed but does not import; its row will say unavailable" >&2
  fi
fi
exec "$venv/bin/python" "$here/rattle_box_peers.py" "$@"
