#!/usr/bin/env bash
# Regenerate launch/config/pipeline.yaml from the code's defaults (after changing a stage's config).
# tests/nodes (test_config_files) fails until this is done.
set -euo pipefail
cd "$(dirname "$0")/.."
{ sed -n '1,/^#   \*\.node\.\*/p' launch/config/pipeline.yaml; build/bin/adit config; } > launch/config/pipeline.yaml.tmp
mv launch/config/pipeline.yaml.tmp launch/config/pipeline.yaml
echo "launch/config/pipeline.yaml: $(grep -c ':' launch/config/pipeline.yaml) lines with keys"
