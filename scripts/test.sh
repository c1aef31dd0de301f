#!/usr/bin/env bash
# Run the test suite, doing all set-up first (idempotent; a warm run reuses everything).
# Extra arguments go to pytest, e.g. scripts/test.sh -k ltl -x
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$ROOT/scripts/setup.sh" --test-data
# shellcheck disable=SC1091
. "$ROOT/scripts/env.sh"
cd "$ROOT"
exec python -m pytest "$@"
