#!/bin/sh
# Renders the material rows shown in docs/materials.md (scenes/materials/*.xml, each
# a row of five spheres) into docs/images/materials/*.png, at each file's own settings.
# Usage: scripts/render-materials.sh [extra pathlab options, e.g. -D spp=64]
set -e
cd "$(dirname "$0")/.."
for scene in scenes/materials/*.xml; do
    name=$(basename "$scene" .xml)
    build/pathlab --scene "$scene" -q -o "docs/images/materials/$name.png" "$@"
    echo "docs/images/materials/$name.png"
done
