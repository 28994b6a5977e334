# Sourced by scripts/models-transfer and scripts/models-transfer-world: the three synthetic validation splits the
# transfer models are chosen on (docs/learning.md), rendered into $OUT_DIR with $WORKERS workers through `cli`:
# the car-height `tusimple` and `dashcam` presets over drawn worlds (seed 3042) and held-out worlds (seed 1042).
render_validation_splits() {
  local preset
  for preset in tusimple dashcam; do
    cli dataset --cases scenes/00_clean --out "$OUT_DIR/val-$preset" --train-frames 150 --seed 3042 --size 640x360 \
      --format jpg --camera "$preset" --vary-world --workers "$WORKERS" --quiet || return 1
  done
  cli dataset --cases scenes/00_clean --out "$OUT_DIR/val-heldout" --train-frames 200 --seed 1042 --size 640x360 \
    --format jpg --vary-world --heldout --workers "$WORKERS" --quiet
}
