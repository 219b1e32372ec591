#!/usr/bin/env bash
# Issue 30's pictures (docs/images/issue30/), rendered on this machine (lavapipe):
# - tones.jpg: the built-in face at the skin model's three tones (--skin-tone light,
#   medium, dark; rows) under three lights (columns): soft front (the key light on
#   the view axis, strong ambient), hard side (90 degrees, almost no ambient) and back
#   light (165 degrees round: the ears glow by transmittance);
# - texturing.jpg: the Lee Perry-Smith head close, pre- (left) and post-scatter
#   (right) texturing (needs ../shared/assets beside the project);
# - wrinkles.jpg: the built-in face's six expressions of Table 8.1 (columns: joy,
#   surprise, fear, anger, disgust, sad) without (top row, --no-wrinkles) and with
#   their wrinkles (bottom row), under a light from above that rakes the creases;
#   wrinkles_compound.jpg: surprise, then surprise and anger together (Figure 8.5:
#   anger cancels the forehead's wrinkles and creases the brows).
# - colour_states.jpg: the appearance rig's maps (thesis ch. 7.4) over the built-in
#   face, one column a state (neutral, joy, surprise, fear, anger, disgust, sad,
#   exercise, alcohol, blush); rows: the rig's haemoglobin, the albedo at 1% melanin,
#   the albedo at the light tone's (the colour_states example).
#
#   bash tools/pictures_issue30.sh
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --features tools --bin dermis --example montage --example colour_states
D=target/release/dermis
M=target/release/examples/montage
T=$(mktemp -d)
OUT=docs/images/issue30
mkdir -p "$OUT"
: > "$OUT/commands.txt"
run() { # name, args...
  local n=$1; shift
  echo "+ dermis render $* --out $n" >> "$OUT/commands.txt"
  "$D" render --frames 1 --warmup 0 "$@" --out "$T/$n" > /dev/null
}
lights=(
  "--light-azimuth 0 --light-elevation 15 --ambient 0.6"
  "--light-azimuth 90 --light-elevation 0 --ambient 0.02"
  "--light-azimuth 165 --light-elevation 10 --ambient 0.05"
)
tiles=()
for tone in light medium dark; do
  for k in 0 1 2; do
    # shellcheck disable=SC2086
    run "$tone-$k" --skin-tone "$tone" --width 360 --height 360 --shot close ${lights[$k]}
    tiles+=("$T/$tone-$k/frame.png")
  done
done
"$M" "$OUT/tones.jpg" 3 "${tiles[@]}"
rake="--light-azimuth 25 --light-elevation 55 --ambient 0.15"
top=()
bottom=()
for e in joy surprise fear anger disgust sad; do
  # shellcheck disable=SC2086
  run "$e-plain" --morph-weights "$e=1" --no-wrinkles --width 300 --height 360 --shot close $rake
  # shellcheck disable=SC2086
  run "$e" --morph-weights "$e=1" --width 300 --height 360 --shot close $rake
  top+=("$T/$e-plain/frame.png")
  bottom+=("$T/$e/frame.png")
done
"$M" "$OUT/wrinkles.jpg" 6 "${top[@]}" "${bottom[@]}"
# shellcheck disable=SC2086
run both --morph-weights "surprise=1,anger=1" --width 300 --height 360 --shot close $rake
"$M" "$OUT/wrinkles_compound.jpg" 2 "$T/surprise/frame.png" "$T/both/frame.png"
echo "+ colour_states $OUT/colour_states.jpg" >> "$OUT/commands.txt"
target/release/examples/colour_states "$OUT/colour_states.jpg"
LPS=../shared/assets/lee-perry-smith/LeePerrySmith.glb
if [ -f "$LPS" ]; then
  for t in pre post; do
    run "lps-$t" --scene "$LPS" --shot close --width 480 --height 480 --texturing "$t" \
      --light-azimuth 40 --light-elevation 20
  done
  "$M" "$OUT/texturing.jpg" 2 "$T/lps-pre/frame.png" "$T/lps-post/frame.png"
fi
rm -rf "$T"
