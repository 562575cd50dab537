#!/usr/bin/env bash
# make demo: the default study (workflows/default.yaml) on a synthetic patient,
# end to end. Safe to interrupt and run again at any point: the patient and
# the study are created once, `mmm run` recomputes only what is missing, and
# the landmark task is picked up in whatever state it was left.
#   demo.sh MMM ATLAS_DIR DATA_DIR DEMO_DIR JOBS MANUAL [NODE.PARAM=VALUE ...]
# The optional settings change the study's parameters (mmm study set) before
# it runs; the end-to-end test (tests/e2e) walks a shorter part of the trial.
# DICOM=1 in the environment: the patient's radiographs are also written as
# DICOM files (with an invented identity) and the study is given those, with
# the same calibration (patient_1_dicom, studies/patient_1_dicom).
set -euo pipefail
mmm=$1 atlas=$2 data=$3 demo=$4 jobs=$5 manual=${6:-0}
settings=("${@:7}")
suffix="" image=png synth_flags=()
if [[ "${DICOM:-0}" == 1 ]]; then suffix=_dicom image=dcm synth_flags=(--dicom); fi
patient=$demo/patient_1$suffix
root=$demo/studies
study=$root/patient_1$suffix
operator=scripted-operator
stage() { echo "== mmm demo: $* =="; }

stage "synthetic patient 1: a deformed atlas (the truth) and its calibrated frontal/lateral radiographs"
if [[ ! -f $patient/ground_truth.json ]]; then
  "$mmm" patient synth --atlas "$atlas" --seed 1 -o "$patient" "${synth_flags[@]}"
fi

stage "the default study ($study)"
if [[ ! -f $study/study.db ]]; then
  rm -rf "$study"  # a creation interrupted before it finished
  mkdir -p "$root"
  "$mmm" study create "$study" -w workflows/default.yaml \
    --input atlas="$atlas" \
    --input calibration="$patient/radiographs/views.json" \
    --input frontal="$patient/radiographs/frontal.$image" \
    --input lateral="$patient/radiographs/lateral.$image" --input patient=P001 \
    --input model="$data/gait2392/Pipelines/reference/subject01_simbody.osim" \
    --input trial="$data/gait2392/Pipelines/subject01_walk1.trc"
fi
if [[ ${#settings[@]} -gt 0 ]]; then
  "$mmm" study set "$study" "${settings[@]}"  # the same values again change nothing
fi

stage "run to the landmark station"
set +e
"$mmm" run "$study" -j "$jobs"
code=$?
set -e
if [[ $code -ne 0 && $code -ne 3 ]]; then
  exit "$code"
fi

if [[ $code -eq 3 ]]; then
  task=$("$mmm" worklist --root "$root" --json | python3 -c '
import json, sys
for t in json.load(sys.stdin):
    if t["study"] == sys.argv[1] and t["node"] == "landmarks" and t["state"] in ("open", "claimed"):
        print(t["task"], t["state"], t["assignee"])
        break' "patient_1$suffix")
  read -r id state assignee <<<"$task"
  if [[ $manual == 1 ]]; then
    cat <<EOT
== mmm demo: the study waits for you at the landmark station (task $id) ==
  Place the landmarks by hand in the browser:
    $mmm operator add YOUR_NAME --root $root      (prints your sign-in token once)
    $mmm serve --root $root -j $jobs              (then open http://127.0.0.1:8080)
  or on the command line: $mmm task show $id --root $root
  Once your landmarks are accepted the study finishes by itself (or run: $mmm run $study).
EOT
    exit 0
  fi
  stage "SCRIPTED OPERATOR (not a person): landmark clicks from the patient's ground truth + 1.5 px noise"
  # The scripted operator signs in like a person: with its own token, kept
  # in a file only this account can read.
  # A new token when there is none or when the root no longer knows the
  # operator (its studies folder was removed for a fresh study).
  token_file=$demo/$operator.token
  if [[ ! -s $token_file ]] ||
    ! "$mmm" operator list --root "$root" | grep -q "^$operator "; then
    (umask 077 && "$mmm" operator add "$operator" --root "$root" --replace >"$token_file")
  fi
  if [[ $state == open ]]; then
    "$mmm" task claim "$id" --root "$root" --token-file "$token_file"
  elif [[ $assignee != "$operator" ]]; then
    echo "task $id is claimed by $assignee; leaving it to them (or: mmm task release $id)" >&2
    exit 1
  fi
  "$mmm" patient clicks "$patient" -o "$demo/scripted_clicks.json" --seed 1
  stage "submit; the study resumes: scaling, motion, hulls, wrapping, fibres"
  "$mmm" task submit "$id" --root "$root" --token-file "$token_file" \
    --file "$demo/scripted_clicks.json" -j "$jobs"
fi

"$mmm" status "$study"
stage "the study report"
"$mmm" report "$study" --truth "$patient" -j "$jobs"
cat <<EOT
== mmm demo: done ==
  Report:   $study/report/index.html  (open it in a browser; it needs no network)
  Study:    $study  (mmm status / mmm explain / mmm audit show)
  Outputs:  $study/outputs/ -- patient_atlas/, overlay.png (scaled bones on the radiographs),
            angle_plot.svg, wrapping_plot.svg, fibre_picture.png, *.csv;
            ParaView: wrapping_animation/wrapping.pvd and fibres_animation/fibres.pvd
  By hand instead of the scripted operator: make demo MANUAL=1 (a fresh study: rm -rf $root)
EOT
