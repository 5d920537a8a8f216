#!/usr/bin/env bash
# Runs COMMAND as in Gradescope's container (Docker's defaults): root, CAP_SYS_ADMIN dropped from
# the capability bounding set, and Docker's seccomp refusals (tools/gradescope-emulation.py). The
# grader's sandbox must hold its required walls there: `tools/gradescope-emulation.sh
# target/release/grader sandbox --check`. Needs util-linux's setpriv and Debian's python3-seccomp.
set -euo pipefail
[ $# -ge 1 ] || { echo "usage: $0 COMMAND [ARG...]" >&2; exit 2; }
here="$(cd "$(dirname "$0")" && pwd)"
exec setpriv --bounding-set -sys_admin --inh-caps -sys_admin /usr/bin/python3 "$here/gradescope-emulation.py" "$@"
