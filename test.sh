#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Install what is missing, build (and the fuzz targets), run the default test suite (long runs:
# ctest -L validation).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
"$root/scripts/setup.sh" --fuzz
ctest --test-dir "$root/build" --output-on-failure -LE validation -j 2 "$@"
