#!/usr/bin/env python3
"""DICOM radiographs of a synthetic patient, written by mmm and by another tool.

A synthetic patient is made with `mmm patient synth --dicom` (slot-scanning
views; PNG + views.json, and DICOM files written by mmm through GDCM). The
same pixels are then written again by pydicom, from scratch, with the
geometry the patient was rendered with, in variants a clinic's systems
produce:

  pydicom_mono2     DX, MONOCHROME2, native explicit VR little endian,
                    Imager Pixel Spacing only, the file's window.
  pydicom_mono1_rle DX, MONOCHROME1 (inverted samples), RLE Lossless, Pixel
                    Spacing calibrated to the patient (GEOMETRY) beside
                    Imager Pixel Spacing, the magnification, no window.
  pydicom_exam      the pydicom_mono2 files in one folder per series,
                    named after the patient, given as one folder for both
                    views.

Each is given to a study (load_radiographs, calibrated from the DICOM
attributes, slot-scanning model) and run. Checked:
  - every variant gives the same pixels as the PNG (exactly);
  - every variant gives the same calibration as mmm's own DICOM files, and
    that calibration is the PNG's views.json up to where the world origin
    is (DICOM attributes do not say where the patient stands): one
    translation maps one onto the other for both views, to 1e-6 mm;
  - no study folder contains the identity written into the files, nor the
    exam's folder names.

Usage: dicom_interop_test.py --mmm MMM --atlas ATLAS_DIR --work DIR
Needs pydicom, numpy and PIL (Debian: python3-pydicom, python3-numpy,
python3-pil) in the interpreter that runs it.
"""

import argparse
import base64
import io
import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pydicom
from PIL import Image
from pydicom.dataset import Dataset, FileMetaDataset
from pydicom.uid import ExplicitVRLittleEndian, RLELossless

DX_FOR_PRESENTATION = "1.2.840.10008.5.1.4.1.1.1.1"
IDENTITY = {
    "PatientName": "INTEROP^PATIENT^PYDICOM",
    "PatientID": "INTEROP-4242",
    "PatientBirthDate": "19800229",
    "StudyDate": "20261129",
    "InstitutionName": "INTEROP CLINIC",
}
FORBIDDEN = [b"INTEROP^PATIENT", b"INTEROP-4242", b"19800229", b"20261129", b"INTEROP CLINIC",
             b"INTEROP_PATIENT_EXAM", b"SYNTHETIC^PATIENT", b"SYN-5"]
WORKFLOW = """mmm_workflow: 1
name: dicom_interop
inputs:
  frontal: {type: File}
  lateral: {type: File}
nodes:
  - {id: radiographs, type: load_radiographs, params: {model: slot-scanning}, inputs: {frontal: study.frontal, lateral: study.lateral}}
outputs: {pair: radiographs.radiographs}
"""


def fail(message):
    print(f"FAIL: {message}", file=sys.stderr)
    sys.exit(1)


def run(args, log):
    result = subprocess.run([str(a) for a in args], capture_output=True, text=True)
    log.write(f"$ {' '.join(str(a) for a in args)}\n{result.stdout}{result.stderr}\n")
    if result.returncode != 0:
        fail(f"{' '.join(str(a) for a in args)} exited {result.returncode}:\n{result.stderr}")
    return result.stdout


def png_pixels(data):
    image = Image.open(io.BytesIO(data))
    return np.array(image, dtype=np.uint16)


def write_pydicom(path, pixels, geometry, uid, mono1_rle):
    """One view written by pydicom from scratch: pixels and the geometry."""
    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID = DX_FOR_PRESENTATION
    meta.MediaStorageSOPInstanceUID = uid
    meta.TransferSyntaxUID = ExplicitVRLittleEndian
    ds = Dataset()
    ds.file_meta = meta
    ds.is_little_endian = True
    ds.is_implicit_VR = False
    ds.SOPClassUID = DX_FOR_PRESENTATION
    ds.SOPInstanceUID = uid
    ds.Modality = "DX"
    for keyword, value in IDENTITY.items():
        setattr(ds, keyword, value)
    ds.ViewPosition = geometry["view_position"]
    ds.PatientOrientation = geometry["patient_orientation"]
    sid, sod, pitch = geometry["sid"], geometry["sod"], geometry["pitch"]
    ds.DistanceSourceToDetector = sid
    ds.DistanceSourceToPatient = sod
    ds.ImagerPixelSpacing = [pitch[0], pitch[1]]
    ds.SamplesPerPixel = 1
    ds.Rows, ds.Columns = pixels.shape
    ds.BitsAllocated = 16
    ds.BitsStored = 16
    ds.HighBit = 15
    ds.PixelRepresentation = 0
    if mono1_rle:
        ds.PhotometricInterpretation = "MONOCHROME1"
        ds.PixelSpacing = [pitch[0] * sod / sid, pitch[1] * sod / sid]
        ds.PixelSpacingCalibrationType = "GEOMETRY"
        ds.EstimatedRadiographicMagnificationFactor = sid / sod
        stored = (65535 - pixels).astype(np.uint16)
        ds.PixelData = stored.astype("<u2").tobytes()
        ds.compress(RLELossless, stored)
    else:
        ds.PhotometricInterpretation = "MONOCHROME2"
        ds.WindowCenter = 30000
        ds.WindowWidth = 50000
        ds.PixelData = pixels.astype("<u2").tobytes()
    path.parent.mkdir(parents=True, exist_ok=True)
    ds.save_as(str(path), write_like_original=False)


def geometry_of(dicom_file):
    """The geometry mmm wrote into its own DICOM file, read by pydicom."""
    ds = pydicom.dcmread(str(dicom_file))
    return {
        "view_position": ds.ViewPosition,
        "patient_orientation": list(ds.PatientOrientation),
        "sid": float(ds.DistanceSourceToDetector),
        "sod": float(ds.DistanceSourceToPatient),
        "pitch": [float(v) for v in ds.ImagerPixelSpacing],
    }


def study_pair(args, name, frontal, lateral, log):
    """Runs load_radiographs on the two inputs; returns the pair document."""
    workflow = args.work / "interop.yaml"
    workflow.write_text(WORKFLOW)
    study = args.work / "studies" / name
    run([args.mmm, "study", "create", study, "--workflow", workflow,
         "--input", f"frontal={frontal}", "--input", f"lateral={lateral}"], log)
    run([args.mmm, "run", study], log)
    exported = sorted((study / "outputs").glob("pair*"))
    if len(exported) != 1:
        fail(f"{name}: expected one exported pair in {study / 'outputs'}, found {exported}")
    everything = b"".join(p.read_bytes() for p in study.rglob("*") if p.is_file())
    for forbidden in FORBIDDEN:
        if forbidden in everything:
            fail(f"{name}: the study folder contains {forbidden!r}")
    return json.loads(exported[0].read_text())


def normalised(P):
    """A projection matrix scaled so that its depth row has a unit direction."""
    P = np.asarray(P, dtype=float)
    return P / np.linalg.norm(P[2, :3])


def check_same_up_to_translation(name, views, reference):
    """views[k].P == reference[k].P * [I t; 0 1] with one t for both views."""
    rows, rhs = [], []
    for view, ref in zip(views, reference):
        P, R = normalised(view["P"]), normalised(ref["P"])
        if np.abs(P[:, :3] - R[:, :3]).max() > 1e-9 * np.abs(R[:, :3]).max():
            fail(f"{name}: view {view['name']} differs from views.json beyond a translation")
        rows.append(P[:, :3])
        rhs.append(R[:, 3] - P[:, 3])
    A, b = np.vstack(rows), np.concatenate(rhs)
    t, *_ = np.linalg.lstsq(A, b, rcond=None)
    residual = A @ t - b
    # In pixels: the largest misfit of the common translation, as a point's
    # displacement in mm (the matrices map mm to pixels at ~2.6 px/mm).
    worst = np.abs(residual).max()
    if worst > 1e-6:
        fail(f"{name}: no single translation maps the calibration onto views.json "
             f"(residual {worst:.3g})")
    return t


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--mmm", type=Path, required=True)
    parser.add_argument("--atlas", type=Path, required=True)
    parser.add_argument("--work", type=Path, required=True)
    args = parser.parse_args()
    if args.work.exists():
        shutil.rmtree(args.work)
    args.work.mkdir(parents=True)
    log = open(args.work / "log.txt", "w")

    patient = args.work / "patient"
    run([args.mmm, "patient", "synth", "--atlas", args.atlas, "--seed", "5", "--dicom",
         "-o", patient], log)
    radiographs = patient / "radiographs"
    views_json = json.loads((radiographs / "views.json").read_text())["views"]
    pixels = {v: png_pixels((radiographs / f"{v}.png").read_bytes()) for v in ("frontal", "lateral")}
    geometry = {v: geometry_of(radiographs / f"{v}.dcm") for v in ("frontal", "lateral")}

    variants = {"mmm_gdcm": {v: radiographs / f"{v}.dcm" for v in ("frontal", "lateral")}}
    for name, mono1_rle in (("pydicom_mono2", False), ("pydicom_mono1_rle", True)):
        variants[name] = {}
        for k, view in enumerate(("frontal", "lateral")):
            path = args.work / name / f"{view}.dcm"
            write_pydicom(path, pixels[view], geometry[view],
                          f"2.25.{4242000 + 10 * k + int(mono1_rle)}", mono1_rle)
            variants[name][view] = path
    exam = args.work / "INTEROP_PATIENT_EXAM"
    for view in ("frontal", "lateral"):
        target = exam / f"SERIES_{view.upper()}" / "IM0001.dcm"
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(variants["pydicom_mono2"][view], target)
    variants["pydicom_exam"] = {"frontal": exam, "lateral": exam}

    reference = None
    for name, files in variants.items():
        pair = study_pair(args, name, files["frontal"], files["lateral"], log)
        views = pair["calibration"]["views"]
        for view in views:
            image = pair["images"][view["image"]]
            decoded = png_pixels(base64.b64decode(image["png_base64"]))
            if not np.array_equal(decoded, pixels[view["name"]]):
                diff = np.abs(decoded.astype(int) - pixels[view["name"]].astype(int)).max()
                fail(f"{name}: view {view['name']}: pixels differ from the PNG (max {diff})")
            if len(image.get("sop_instance_uid_sha256", "")) != 64:
                fail(f"{name}: view {view['name']}: no SOP Instance UID hash carried")
            if view["model"] != "slot-scanning":
                fail(f"{name}: view {view['name']} is {view['model']}")
        if reference is None:
            reference = views
        for view, ref in zip(views, reference):
            if np.abs(np.asarray(view["P"]) - np.asarray(ref["P"])).max() > 1e-9 * np.abs(
                    np.asarray(ref["P"])).max():
                fail(f"{name}: view {view['name']}: calibration differs from mmm's own DICOM")
        t = check_same_up_to_translation(name, views, views_json)
        print(f"{name}: pixels identical to the PNG; calibration = views.json moved by "
              f"({t[0]:.1f}, {t[1]:.1f}, {t[2]:.1f}) mm; nothing identifying stored")
    print("dicom interop: 4 variants, all consistent")


if __name__ == "__main__":
    main()
