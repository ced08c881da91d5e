#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Install what is missing, build, run the default test suite (long runs: ctest -L validation).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
"$root/scripts/setup.sh"
ctest --test-dir "$root/build" --output-on-failure -LE validation -j 2 "$@"
