#!/usr/bin/env bash
# Regenerates the golden images from the current renderer and says which ones changed.
# Usage: tests/golden/update.sh [build-dir]   (default: build)
set -euo pipefail
cd "$(dirname "$0")/../.."
build="${1:-build}"
cmake --build "$build" --target vdmsim_render_tests
VDMSIM_UPDATE_GOLDEN=1 "$build/tests/vdmsim_render_tests" --gtest_filter='GoldenImages.*:-*Twice*:*Catches*' | grep '^golden ' || true
echo "Review the changes (git diff --stat tests/golden) and look at the images before committing them."
