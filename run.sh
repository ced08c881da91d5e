#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Install what is missing, build, run a case (default: the demo case) and say where results are.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
"$root/scripts/setup.sh"
case_file=${1:-$root/cases/demo_beam_impact/case.yaml}
shift || true
exec "$root/build/app/arlequin" run "$case_file" "$@"
