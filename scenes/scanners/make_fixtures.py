#!/usr/bin/env python3
"""Writes the scanner-format fixtures (issue 42) with the real tools: pynrrd, tifffile, pydicom.

Every fixture holds the same asymmetric 5 x 3 x 4 volume, value 1 + x + 5 y + 15 z at voxel
(x, y, z) (all distinct, so a swapped, mirrored or shifted axis shows), voxel spacing
(0.5, 0.25, 2.0) and the first voxel centred at (10, -5, 3); `reference.mha` (written here as plain
MetaImage text and bytes) is that volume, and `reference-origin0.mha` the same at the origin (TIFF
has no origin). Files are stored in their own axis order, mirrored or permuted where a format
allows it, so that reading them back as the reference checks the reader's geometry.

    python3 make_fixtures.py OUT_DIR
"""
import gzip  # noqa: F401  (pynrrd's gzip encoding uses it)
import os
import sys

import numpy as np
import nrrd
import pydicom
import tifffile
from pydicom.dataset import Dataset, FileMetaDataset
from pydicom.uid import (
    ExplicitVRBigEndian,
    ExplicitVRLittleEndian,
    ImplicitVRLittleEndian,
    JPEGBaseline8Bit,
    generate_uid,
)

NX, NY, NZ = 5, 3, 4
SPACING = (0.5, 0.25, 2.0)
ORIGIN = (10.0, -5.0, 3.0)

x, y, z = np.meshgrid(np.arange(NX), np.arange(NY), np.arange(NZ), indexing="ij")
VOLUME = (1 + x + 5 * y + 15 * z).astype(np.uint16)  # indexed [x, y, z]


def write_mha(path, origin):
    data = np.asfortranarray(VOLUME).astype("<u2")
    header = (
        "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
        f"Offset = {origin[0]!r} {origin[1]!r} {origin[2]!r}\n"
        f"ElementSpacing = {SPACING[0]!r} {SPACING[1]!r} {SPACING[2]!r}\n"
        f"DimSize = {NX} {NY} {NZ}\nElementType = MET_USHORT\nElementDataFile = LOCAL\n"
    )
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(data.tobytes(order="F"))


def nrrd_fixtures(out):
    directions = np.diag(SPACING)
    base = {"space": "left-posterior-superior", "space directions": directions,
            "space origin": np.array(ORIGIN), "kinds": ["domain"] * 3}
    nrrd.write(os.path.join(out, "raw.nrrd"), VOLUME, dict(base, encoding="raw"), index_order="F")
    nrrd.write(os.path.join(out, "gzip.nrrd"), VOLUME.astype(np.float32),
               dict(base, encoding="gzip", endian="big"), index_order="F")
    nrrd.write(os.path.join(out, "detached.nhdr"), VOLUME.astype(np.int16),
               dict(base, encoding="gzip"), index_order="F", detached_header=True)
    # x mirrored: the file's first sample is the volume's last along x.
    mirrored = dict(base, encoding="raw")
    mirrored["space directions"] = np.diag([-SPACING[0], SPACING[1], SPACING[2]])
    mirrored["space origin"] = np.array([ORIGIN[0] + (NX - 1) * SPACING[0], ORIGIN[1], ORIGIN[2]])
    nrrd.write(os.path.join(out, "mirrored-x.nrrd"), VOLUME[::-1, :, :].copy(), mirrored,
               index_order="F")
    # File axes (y, x, z): its first axis steps along world y.
    permuted = dict(base, encoding="raw")
    permuted["space directions"] = np.array([[0, SPACING[1], 0], [SPACING[0], 0, 0],
                                             [0, 0, SPACING[2]]])
    nrrd.write(os.path.join(out, "permuted-xy.nrrd"), VOLUME.transpose(1, 0, 2).copy(), permuted,
               index_order="F")


def tiff_fixtures(out):
    zyx = VOLUME.transpose(2, 1, 0)  # pages, rows, columns
    resolution = (1 / SPACING[0], 1 / SPACING[1])
    meta = {"spacing": SPACING[2], "unit": "um"}
    tifffile.imwrite(os.path.join(out, "stack-u16.tif"), zyx, imagej=True,
                     resolution=resolution, metadata=meta)
    tifffile.imwrite(os.path.join(out, "stack-u8-deflate.tif"), zyx.astype(np.uint8),
                     imagej=True, resolution=resolution, metadata=meta, compression="zlib")
    tifffile.imwrite(os.path.join(out, "stack-f32.tif"), zyx.astype(np.float32),
                     imagej=True, resolution=resolution, metadata=meta)
    # A folder of single-page float TIFFs, named so that only a natural sort orders them.
    folder = os.path.join(out, "tiff-folder")
    os.makedirs(folder, exist_ok=True)
    for k in range(NZ):
        tifffile.imwrite(os.path.join(folder, f"slice_{k + 8}.tif"), zyx[k].astype(np.float32),
                         imagej=True, resolution=resolution, metadata=meta)


def dicom_slice(path, pixels, position, orientation, pixel_spacing, syntax, series, slope,
                intercept, stored_bits=16, instance=1):
    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID = "1.2.840.10008.5.1.4.1.1.2"  # CT Image Storage
    meta.MediaStorageSOPInstanceUID = generate_uid()
    meta.TransferSyntaxUID = syntax
    ds = Dataset()
    ds.file_meta = meta
    ds.SOPClassUID = meta.MediaStorageSOPClassUID
    ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
    ds.Modality = "CT"
    ds.SeriesInstanceUID = series
    ds.StudyInstanceUID = generate_uid()
    ds.InstanceNumber = instance
    ds.ImagePositionPatient = [float(v) for v in position]
    ds.ImageOrientationPatient = [float(v) for v in orientation]
    ds.PixelSpacing = [float(v) for v in pixel_spacing]
    ds.SliceThickness = 1.0
    ds.SamplesPerPixel = 1
    ds.PhotometricInterpretation = "MONOCHROME2"
    ds.Rows, ds.Columns = pixels.shape
    ds.BitsAllocated = 16
    ds.BitsStored = stored_bits
    ds.HighBit = stored_bits - 1
    ds.PixelRepresentation = 1
    ds.RescaleSlope = slope
    ds.RescaleIntercept = intercept
    ds.RescaleType = "HU"
    if syntax == JPEGBaseline8Bit:
        from pydicom.encaps import encapsulate
        ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 8, 8, 7, 0
        ds.PixelData = encapsulate([b"\xff\xd8\xff\xd9"])
        ds["PixelData"].VR = "OB"
    else:
        # pydicom writes PixelData's bytes as given: in the syntax's byte order.
        order = ">" if syntax == ExplicitVRBigEndian else "<"
        ds.PixelData = pixels.astype(order + "i2").tobytes()
    ds.save_as(path, enforce_file_format=True)


def dicom_fixtures(out):
    # Axial, explicit VR little endian, HU = raw - 1024: stored raw = value + 24. Files named
    # against their position order.
    folder = os.path.join(out, "dicom-axial")
    os.makedirs(folder, exist_ok=True)
    series = generate_uid()
    for k in range(NZ):
        position = (ORIGIN[0], ORIGIN[1], ORIGIN[2] + k * SPACING[2])
        dicom_slice(os.path.join(folder, f"IM{NZ - k:04d}"), VOLUME[:, :, k].T + 24, position,
                    (1, 0, 0, 0, 1, 0), (SPACING[1], SPACING[0]), ExplicitVRLittleEndian, series,
                    1, -1024, instance=k + 1)
    # Axial mirrored along x (rows run towards -x), implicit VR, 12 stored bits, HU = raw / 2 -
    # 1000: stored raw = 2 value. The normal (-x) x (+y) = -z: slices are ordered downwards.
    folder = os.path.join(out, "dicom-mirrored")
    os.makedirs(folder, exist_ok=True)
    series = generate_uid()
    for k in range(NZ):
        position = (ORIGIN[0] + (NX - 1) * SPACING[0], ORIGIN[1], ORIGIN[2] + k * SPACING[2])
        pixels = VOLUME[::-1, :, k].T * 2
        dicom_slice(os.path.join(folder, f"slice{k}.dcm"), pixels, position, (-1, 0, 0, 0, 1, 0),
                    (SPACING[1], SPACING[0]), ImplicitVRLittleEndian, series, 0.5, -1000,
                    stored_bits=12)
    # Coronal, explicit VR big endian: rows along x, columns along z, slices along y (normal -y).
    folder = os.path.join(out, "dicom-coronal")
    os.makedirs(folder, exist_ok=True)
    series = generate_uid()
    for m in range(NY):
        position = (ORIGIN[0], ORIGIN[1] + m * SPACING[1], ORIGIN[2])
        pixels = VOLUME[:, m, :].T + 1000  # rows: z; columns: x; HU = raw - 2000
        dicom_slice(os.path.join(folder, f"c{m}.dcm"), pixels, position, (1, 0, 0, 0, 0, 1),
                    (SPACING[2], SPACING[0]), ExplicitVRBigEndian, series, 1, -2000)
    # A JPEG slice: refused by the name of its transfer syntax.
    folder = os.path.join(out, "dicom-jpeg")
    os.makedirs(folder, exist_ok=True)
    dicom_slice(os.path.join(folder, "jpeg.dcm"), VOLUME[:, :, 0].T, ORIGIN, (1, 0, 0, 0, 1, 0),
                (SPACING[1], SPACING[0]), JPEGBaseline8Bit, generate_uid(), 1, -1024)


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    write_mha(os.path.join(out, "reference.mha"), ORIGIN)
    write_mha(os.path.join(out, "reference-origin0.mha"), (0.0, 0.0, 0.0))
    nrrd_fixtures(out)
    tiff_fixtures(out)
    dicom_fixtures(out)
    print(f"scanner fixtures written to {out} (pynrrd {nrrd.__version__}, tifffile "
          f"{tifffile.__version__}, pydicom {pydicom.__version__})")


if __name__ == "__main__":
    main()
