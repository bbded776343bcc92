#!/usr/bin/env bash
# Renders the preview of every scene preset (scenes/presets/*.yaml) with the
# DAVIS346-like preview rig and copies the tone-mapped PNGs to docs/previews/.
#   scripts/render_previews.sh [build-dir]      (default: build/release)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build/release}"
evio="$build/bin/evio"
[ -x "$evio" ] || { echo "render_previews: $evio not found (build the 'evio' target first)" >&2; exit 1; }
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
mkdir -p "$root/docs/previews"
for scene in "$root"/scenes/presets/*.yaml; do
  name="$(basename "$scene" .yaml)"
  [ "$name" = preview_rig ] && continue
  "$evio" render "$scene" --camera "$root/scenes/presets/preview_rig.yaml" -o "$out/$name" --quiet
  cp "$out/$name/preview.png" "$root/docs/previews/$name.png"
  echo "docs/previews/$name.png"
done
