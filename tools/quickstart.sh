#!/usr/bin/env bash
# Fresh machine to first result: installs dependencies, builds, then derives, emits and simulates the
# rolling ball of Müller (2023), Sec. 4 (models/rolling_ball.yaml).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/install-deps.sh
bash tools/build.sh --target hamel
hamel=build/bin/hamel
model=models/rolling_ball.yaml
echo
echo "== hamel derive $model"
$hamel derive $model
echo
echo "== hamel emit $model -o build/generated/rolling_ball"
$hamel emit $model -o build/generated/rolling_ball
echo
echo "== hamel simulate $model --t-end 2 --init vx=0.5,vy=0.2 --sample 0.5"
$hamel simulate $model --t-end 2 --init vx=0.5,vy=0.2 --sample 0.5 --out -
