#!/usr/bin/env bash
# Gradescope runs this once, as root, on its Ubuntu/Debian image, from the
# unpacked bundle (/autograder/source): install the Debian packages ./course
# needs (its own list, read from course/course), then configure and build the
# lab's graded tests once against the stubs, so that run_autograder only
# recompiles the student's files. Written by ./course autograder labNN.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"

# One package list: the `packages=(...)` array of the course script.
eval "$(sed -n '/^packages=(/,/)/p' "$here/course/course")"
missing=()
for package in "${packages[@]}"; do
  status="$(dpkg-query -W -f='${Status}' "$package" 2>/dev/null || true)"
  [[ "$status" == "install ok installed" ]] || missing+=("$package")
done
if (( ${#missing[@]} )); then
  if (( EUID != 0 )); then
    echo "setup.sh: missing Debian packages (${missing[*]}); run me as root" >&2
    exit 2
  fi
  echo "installing ${missing[*]}"
  apt-get update
  DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${missing[@]}"
fi

exec python3 "$here/autograder_run.py" setup
