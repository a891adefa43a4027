#!/usr/bin/env bash
# The stills of `hamel animate` in the README and docs/animate.md: the satellite's phase experiment (paper Sec. 6c,
# models/satellite_se3_tree.yaml) and MuJoCo's humanoid imported with `hamel import`, tumbling without gravity from
# a start with its base and some joints turning (momentum conserved: the torso counter-rotates). Writes the
# pages into build/animate/ and the screenshots (headless Chromium, software WebGL) into docs/figures/.
#   bash tools/animate-stills.sh [build/bin/hamel]
set -euo pipefail
cd "$(dirname "$0")/.."
hamel=${1:-build/bin/hamel}
out=build/animate
mkdir -p "$out" docs/figures
browser=$(command -v chromium-headless-shell || command -v chromium || true)
[ -n "$browser" ] || { echo "animate-stills: chromium-headless-shell (or chromium) is not installed (tools/install-deps.sh)" >&2; exit 1; }
path="pi*(cos(2*pi*t) - 1); pi*sin(2*pi*t); pi/2*sin(4*pi*t)"
"$hamel" animate models/satellite_se3_tree.yaml --path "$path" --period 1 --cycles 6 -o "$out/satellite_phase.html"
"$hamel" import /usr/share/mujoco/model/humanoid/humanoid.xml -o "$out/humanoid.yaml" --ignore contacts,limits,gravity
"$hamel" animate "$out/humanoid.yaml" --t-end 2 -o "$out/humanoid.html" \
  --init "wx=0.4,wy=0.2,abdomen_z_dot=1,right_shoulder1_dot=3,left_shoulder2_dot=-3,right_hip_x_dot=1.5,left_knee_dot=-4"
shot() {  # page, time, png
  "$browser" --headless --no-sandbox --use-gl=swiftshader --enable-unsafe-swiftshader --hide-scrollbars \
    --user-data-dir="$out/chromium-profile" --window-size=1000,640 --screenshot="$3" \
    "file://$PWD/$1#t=$2" 2>/dev/null
}
shot "$out/satellite_phase.html" 5.6 docs/figures/animate_satellite_phase.png
shot "$out/humanoid.html" 0.8 docs/figures/animate_humanoid.png
echo "animate-stills: wrote docs/figures/animate_satellite_phase.png and docs/figures/animate_humanoid.png"
