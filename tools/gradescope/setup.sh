#!/usr/bin/env bash
# Gradescope runs this once, as root, on its Ubuntu/Debian image, from the
# unpacked bundle (/autograder/source): install what ./course grade needs, by
# the check ./course itself makes (course/tools/cl/requirements.py: apt as
# root), then configure and build the lab's graded tests once against the
# stubs, so that run_autograder only recompiles the student's files. Written
# by ./course autograder labNN.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"

if ! command -v python3 >/dev/null 2>&1; then
  if (( EUID != 0 )); then
    echo "setup.sh: no python3; run me as root" >&2
    exit 2
  fi
  apt-get update
  DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends python3
fi
python3 "$here/course/tools/cl/requirements.py" grade

exec python3 "$here/autograder_run.py" setup
