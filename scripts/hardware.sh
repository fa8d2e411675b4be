#!/usr/bin/env bash
# The maker pack's checks (docs/hardware/design/check.py): SKiDL's electrical rules check of the
# base station's circuit, the KiCad netlist, bill of materials and pictures in docs/hardware/
# against what the design makes, the Black Pill's pins against firmware/src/main.rs and
# docs/hardware.md, and the computed component values against their requirements.
#   scripts/hardware.sh            check (run by scripts/test.sh)
#   scripts/hardware.sh --update   rewrite the generated files after changing the design
# Python packages are pinned in docs/hardware/design/requirements.txt and installed into
# target/hardware-venv, once: the venv is rebuilt only when the requirements change.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=target/hardware-venv
req=docs/hardware/design/requirements.txt
stamp="$venv/requirements.sha256"
want=$(sha256sum "$req" | cut -d' ' -f1)
if [ ! -x "$venv/bin/python" ] || [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
    python=$(command -v python3.11 || command -v python3)
    echo "hardware: installing the pinned Python packages into $venv" >&2
    rm -rf "$venv"
    if ! "$python" -m venv "$venv" >/dev/null 2>&1; then
        # Debian's own Python keeps venv (ensurepip) in a package of its own.
        rm -rf "$venv"
        sudo=""
        [ "$(id -u)" -eq 0 ] || sudo="sudo"
        $sudo apt-get update -qq
        DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends python3-venv >/dev/null
        python=/usr/bin/python3
        "$python" -m venv "$venv"
    fi
    "$venv/bin/pip" install -q --disable-pip-version-check -r "$req"
    echo "$want" >"$stamp"
fi
cd docs/hardware/design
# SKiDL's working files (its part cache, logs) stay out of the tree; MPLCONFIGDIR likewise.
export MPLCONFIGDIR="$OLDPWD/$venv/mpl"
exec "$OLDPWD/$venv/bin/python" -B check.py "$@"
