#!/usr/bin/env bash
# CTest fixture of the browser test: the default atlas and synthetic patient 1
# (radiographs + ground truth) under FIXTURES, each made once and reused while
# what it is made from does not change.
#   make_patient.sh MMM SOURCE_DIR DATA_DIR FIXTURES
set -euo pipefail
mmm=$1 source_dir=$2 data_dir=$3 fixtures=$4
mkdir -p "$fixtures"
# Remade when missing, or older than the recipe or the mmm that builds it.
recipe=$source_dir/schemas/recipes/vhf_right_leg.yaml
if [[ ! -f $fixtures/atlas/atlas.yaml || $recipe -nt $fixtures/atlas/atlas.yaml ||
  $mmm -nt $fixtures/atlas/atlas.yaml ]]; then
  "$mmm" atlas build "$recipe" -o "$fixtures/atlas" \
    --data "$data_dir"
fi
if [[ ! -f $fixtures/patient_1/ground_truth.json ||
  $fixtures/atlas/atlas.yaml -nt $fixtures/patient_1/ground_truth.json ]]; then
  "$mmm" patient synth --atlas "$fixtures/atlas" --seed 1 -o "$fixtures/patient_1"
fi
echo "fixtures ready: $fixtures/atlas, $fixtures/patient_1"
