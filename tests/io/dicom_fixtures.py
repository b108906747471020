#!/usr/bin/env python3
"""DICOM fixtures with known geometry, written with pydicom at test time (tests/io/dicom_series_test.cpp).

Usage: dicom_fixtures.py OUTDIR. Writes one folder per case and OUTDIR/expected.json:
for each case the folder (or named file) to read, the geometry the reader must report
(LPS mm: DICOM patient coordinates), and the value model: every stored pixel is
round(f(world position)) with f linear, so a correct reader gives voxel (i,j,k) the value
f(origin + direction * diag(spacing) * (i,j,k)) exactly (within 1 for gantry-tilted stacks,
which are resampled). Or the error the reader must give (a substring).
"""
import json
import math
import os
import random
import sys

import numpy as np
import pydicom
from pydicom.dataset import Dataset, FileMetaDataset
from pydicom.uid import ExplicitVRLittleEndian, ImplicitVRLittleEndian, generate_uid

CT = "1.2.840.10008.5.1.4.1.1.2"
MR = "1.2.840.10008.5.1.4.1.1.4"
NM = "1.2.840.10008.5.1.4.1.1.20"
RTDOSE = "1.2.840.10008.5.1.4.1.1.481.2"
RTSTRUCT = "1.2.840.10008.5.1.4.1.1.481.3"
SEG = "1.2.840.10008.5.1.4.1.1.66.4"
COEF = (2.0, 3.0, 5.0)
OFFSET = 1000.0


def f(w):
    return OFFSET + COEF[0] * w[0] + COEF[1] * w[1] + COEF[2] * w[2]


def base(sop, series, modality="CT", implicit=False):
    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID = sop
    meta.MediaStorageSOPInstanceUID = generate_uid()
    meta.TransferSyntaxUID = ImplicitVRLittleEndian if implicit else ExplicitVRLittleEndian
    ds = Dataset()
    ds.file_meta = meta
    ds.is_little_endian = True
    ds.is_implicit_VR = implicit
    ds.SOPClassUID = sop
    ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
    ds.Modality = modality
    ds.StudyInstanceUID = "1.2.826.0.1.3680043.8.498.1"
    ds.SeriesInstanceUID = series
    ds.PatientName = "Fixture^Volscissors"
    return ds


def write_slice(path, series, r, c, pos, ps, rows, cols, k, sop=CT, modality="CT", photometric="MONOCHROME2",
                slope=1.0, inter=0.0, values=None, implicit=False, geometry=True, bits=16):
    ds = base(sop, series, modality, implicit)
    ds.InstanceNumber = k + 1
    if geometry:
        ds.ImagePositionPatient = [float(x) for x in pos]
        ds.ImageOrientationPatient = [float(x) for x in list(r) + list(c)]
    ds.PixelSpacing = [ps[0], ps[1]]  # between rows, between columns
    ds.SliceThickness = 1.0
    ds.Rows, ds.Columns = rows, cols
    ds.SamplesPerPixel = 1
    ds.PhotometricInterpretation = photometric
    ds.BitsAllocated = bits
    ds.BitsStored = 12 if bits == 16 else bits
    ds.HighBit = ds.BitsStored - 1
    ds.PixelRepresentation = 0
    if slope != 1.0 or inter != 0.0:
        ds.RescaleSlope = slope
        ds.RescaleIntercept = inter
    if values is None:
        r_, c_, p_ = np.array(r), np.array(c), np.array(pos)
        v = np.zeros((rows, cols), dtype=np.uint16)
        for j in range(rows):
            for i in range(cols):
                w = p_ + i * ps[1] * r_ + j * ps[0] * c_
                v[j, i] = int(round((f(w) - inter) / slope))
        values = v
    if bits == 1:
        flat = values.astype(np.uint8).ravel()
        ds.PixelData = np.packbits(flat, bitorder="little").tobytes()
    elif bits == 8:
        ds.PixelData = values.astype(np.uint8).tobytes()
    else:
        ds.PixelData = values.astype(np.uint16).tobytes()
    ds.save_as(path, write_like_original=False)
    return path


def series_case(out, name, r, c, step, n, ps=(0.8, 0.6), rows=12, cols=16, p0=(-20.0, 10.0, 30.0), tilt=None,
                **kw):
    folder = os.path.join(out, name)
    os.makedirs(folder)
    r, c = np.array(r, float), np.array(c, float)
    r /= np.linalg.norm(r)
    c /= np.linalg.norm(c)
    nrm = np.cross(r, c)
    series = generate_uid()
    order = list(range(n))
    random.Random(len(name)).shuffle(order)  # files not in slice order
    positions = []
    for k in range(n):
        p = np.array(p0) + k * step * nrm
        if tilt is not None:
            p = p + k * step * math.tan(math.radians(tilt)) * c
        positions.append(p)
    for idx, k in enumerate(order):
        write_slice(os.path.join(folder, "IM%04d" % idx), series, r, c, positions[k], ps, rows, cols, k, **kw)
    direction = np.column_stack([r, c, nrm])
    return {"name": name, "read": folder, "dims": [cols, rows, n], "spacing": [ps[1], ps[0], step],
            "origin": list(map(float, positions[0])), "direction": direction.ravel().tolist(),
            "tolerance": 1.0 if tilt else 0.0, "values": True}


def rot_x(deg):
    a = math.radians(deg)
    return np.array([[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]])


def main(out):
    os.makedirs(out, exist_ok=True)
    cases = []
    cases.append(series_case(out, "axial", (1, 0, 0), (0, 1, 0), 2.5, 6))
    cases.append(series_case(out, "coronal", (1, 0, 0), (0, 0, -1), 2.0, 5))
    cases.append(series_case(out, "sagittal", (0, 1, 0), (0, 0, -1), 1.5, 5))
    R = rot_x(30)
    cases.append(series_case(out, "oblique30x", R @ [1, 0, 0], R @ [0, 1, 0], 2.0, 5))
    R2 = rot_x(-20) @ np.array([[math.cos(0.4), -math.sin(0.4), 0], [math.sin(0.4), math.cos(0.4), 0], [0, 0, 1]])
    cases.append(series_case(out, "oblique_double", R2 @ [1, 0, 0], R2 @ [0, 1, 0], 1.25, 4, implicit=True))
    cases.append(series_case(out, "gantry_tilt15", (1, 0, 0), (0, 1, 0), 2.0, 6, tilt=15.0, rows=24, cols=20))
    c1 = series_case(out, "single_sagittal", (0, 1, 0), (0, 0, -1), 3.0, 1)
    c1["spacing"][2] = 1.0  # SliceThickness
    cases.append(c1)
    c2 = series_case(out, "single_coronal", (1, 0, 0), (0, 0, -1), 3.0, 1)
    c2["spacing"][2] = 1.0
    cases.append(c2)
    m1 = series_case(out, "monochrome1", (1, 0, 0), (0, 1, 0), 2.0, 3, photometric="MONOCHROME1", slope=1.0,
                     inter=-1024.0)
    m1["notes"] = ["MONOCHROME1"]
    cases.append(m1)
    nm = series_case(out, "nm_spacing", (1, 0, 0), (0, 1, 0), 4.0, 3, ps=(4.42, 4.42), sop=NM, modality="NM")
    cases.append(nm)

    # The named file's own series: two series in one folder, the smaller one named.
    folder = os.path.join(out, "two_series")
    os.makedirs(folder)
    big, small = generate_uid(), generate_uid()
    for k in range(7):
        write_slice(os.path.join(folder, "A%02d" % k), big, (1, 0, 0), (0, 1, 0), (0, 0, 2.0 * k), (1, 1), 8, 8, k)
    for k in range(3):
        write_slice(os.path.join(folder, "B%02d" % k), small, (1, 0, 0), (0, 0, -1), (0, 3.0 * k, 0), (1, 1), 8, 8, k)
    cases.append({"name": "named_file_series", "read": os.path.join(folder, "B01"), "dims": [8, 8, 3],
                  "spacing": [1, 1, 3], "origin": [0, 0, 0], "direction": [1, 0, 0, 0, 0, 1, 0, -1, 0],
                  "tolerance": 0.0, "values": True})
    cases.append({"name": "folder_largest", "read": folder, "dims": [8, 8, 7], "spacing": [1, 1, 2],
                  "origin": [0, 0, 0], "direction": [1, 0, 0, 0, 1, 0, 0, 0, 1], "tolerance": 0.0, "values": True,
                  "notes": ["other DICOM series in folder: " + small]})

    # A 3-plane localizer: one series UID, three orientations.
    folder = os.path.join(out, "localizer")
    os.makedirs(folder)
    loc = generate_uid()
    planes = [((1, 0, 0), (0, 1, 0), (0, 0, 1)), ((1, 0, 0), (0, 0, -1), (0, 1, 0)), ((0, 1, 0), (0, 0, -1), (-1, 0, 0))]
    idx = 0
    for p, (r, c, nrm) in enumerate(planes):
        for k in range(3 + p):
            write_slice(os.path.join(folder, "L%02d" % idx), loc, r, c, tuple(5.0 * k * x for x in nrm), (1, 1), 8, 8,
                        idx)
            idx += 1
    cases.append({"name": "localizer_folder", "read": folder, "dims": [8, 8, 5], "spacing": [1, 1, 5],
                  "origin": [0, 0, 0], "direction": [0, 0, -1, 1, 0, 0, 0, -1, 0], "tolerance": 0.0, "values": True,
                  "notes": ["of another orientation"]})
    cases.append({"name": "localizer_named_axial", "read": os.path.join(folder, "L01"), "dims": [8, 8, 3],
                  "spacing": [1, 1, 5], "origin": [0, 0, 0], "direction": [1, 0, 0, 0, 1, 0, 0, 0, 1],
                  "tolerance": 0.0, "values": True})

    # 1-bit pixels are 0/1, not 0/255.
    folder = os.path.join(out, "onebit")
    os.makedirs(folder)
    bits = (np.indices((8, 16)).sum(axis=0) % 3 == 0).astype(np.uint8)
    write_slice(os.path.join(folder, "bits.dcm"), generate_uid(), (1, 0, 0), (0, 1, 0), (0, 0, 0), (1, 1), 8, 16, 0,
                sop=MR, modality="MR", values=bits, bits=1)
    cases.append({"name": "one_bit", "read": os.path.join(folder, "bits.dcm"), "dims": [16, 8, 1],
                  "spacing": [1, 1, 1], "origin": [0, 0, 0], "direction": [1, 0, 0, 0, 1, 0, 0, 0, 1],
                  "tolerance": 0.0, "values": False, "range": [0, 1], "sum": int(bits.sum())})

    # A radiotherapy export: CT + RTDOSE (multi-frame) + RTSTRUCT (no pixels) + SEG + DICOMDIR.
    folder = os.path.join(out, "rt_export")
    os.makedirs(folder)
    ct = generate_uid()
    for k in range(4):
        write_slice(os.path.join(folder, "CT%02d.dcm" % k), ct, (1, 0, 0), (0, 1, 0), (0, 0, 3.0 * k), (1, 1), 8, 8, k)
    dose = base(RTDOSE, generate_uid(), "RTDOSE")
    dose.Rows, dose.Columns, dose.NumberOfFrames = 4, 4, 3
    dose.SamplesPerPixel, dose.PhotometricInterpretation = 1, "MONOCHROME2"
    dose.BitsAllocated, dose.BitsStored, dose.HighBit, dose.PixelRepresentation = 16, 16, 15, 0
    dose.GridFrameOffsetVector = [0, 2, 4]
    dose.PixelData = np.zeros((3, 4, 4), np.uint16).tobytes()
    dose.save_as(os.path.join(folder, "RD.dcm"), write_like_original=False)
    st = base(RTSTRUCT, generate_uid(), "RTSTRUCT")
    st.StructureSetLabel = "fixture"
    st.save_as(os.path.join(folder, "RS.dcm"), write_like_original=False)
    seg = base(SEG, generate_uid(), "SEG")
    seg.Rows, seg.Columns, seg.NumberOfFrames = 8, 8, 1
    seg.SamplesPerPixel, seg.PhotometricInterpretation = 1, "MONOCHROME2"
    seg.BitsAllocated, seg.BitsStored, seg.HighBit, seg.PixelRepresentation = 1, 1, 0, 0
    seg.PixelData = bytes(8)
    seg.save_as(os.path.join(folder, "SEG.dcm"), write_like_original=False)
    dd = FileMetaDataset()
    dd.MediaStorageSOPClassUID = "1.2.840.10008.1.3.10"
    dd.MediaStorageSOPInstanceUID = generate_uid()
    dd.TransferSyntaxUID = ExplicitVRLittleEndian
    ddset = Dataset()
    ddset.file_meta = dd
    ddset.is_little_endian, ddset.is_implicit_VR = True, False
    ddset.FileSetID = "FIXTURE"
    ddset.DirectoryRecordSequence = []
    ddset.save_as(os.path.join(folder, "DICOMDIR"), write_like_original=False)
    cases.append({"name": "rt_export_folder", "read": folder, "dims": [8, 8, 4], "spacing": [1, 1, 3],
                  "origin": [0, 0, 0], "direction": [1, 0, 0, 0, 1, 0, 0, 0, 1], "tolerance": 0.0, "values": True,
                  "notes": ["non-image DICOM object"]})
    cases.append({"name": "rt_export_named_ct", "read": os.path.join(folder, "CT02.dcm"), "dims": [8, 8, 4],
                  "spacing": [1, 1, 3], "origin": [0, 0, 0], "direction": [1, 0, 0, 0, 1, 0, 0, 0, 1],
                  "tolerance": 0.0, "values": True})
    for fname, why in (("RD.dcm", "RT Dose"), ("RS.dcm", "RT Structure Set"), ("SEG.dcm", "Segmentation"),
                       ("DICOMDIR", "DICOMDIR")):
        cases.append({"name": "refuse_" + why.replace(" ", "_"), "read": os.path.join(folder, fname), "error": why})

    # Two slices at one position (several phases in one series): refused, not stacked.
    folder = os.path.join(out, "same_position")
    os.makedirs(folder)
    sp = generate_uid()
    for k in range(3):
        write_slice(os.path.join(folder, "S%02d" % k), sp, (1, 0, 0), (0, 1, 0), (0, 0, 0 if k < 2 else 2), (1, 1), 8,
                    8, k)
    cases.append({"name": "same_position", "read": folder, "error": "same position"})

    with open(os.path.join(out, "expected.json"), "w") as fh:
        json.dump({"coef": COEF, "offset": OFFSET, "cases": cases}, fh, indent=1)


if __name__ == "__main__":
    main(sys.argv[1])
