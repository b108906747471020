#!/usr/bin/env bash
# Bounded libFuzzer run of every reader (issue 11). Builds build-fuzz/ with clang
# (-DVS_FUZZ=ON: ASan + UBSan + libFuzzer), makes a small seed corpus with the project's own
# generator (`volscissors phantom`, `convert`, `render`, `trace`) plus a few hand-made files
# for the formats volscissors does not write, then runs each target for FUZZ_SECONDS
# (default 5; by hand: FUZZ_SECONDS=600 scripts/fuzz.sh, or FUZZ_TARGETS="vti nrrd").
# Exit status 1 if any target found a crash, a leak-free OOM or a timeout; the inputs are
# kept in build-fuzz/fuzz-crashes/<target>/ (turn each into a test in tests/io/).
set -euo pipefail
cd "$(dirname "$0")/.."
FUZZ_BUILD=${FUZZ_BUILD:-build-fuzz}
FUZZ_SECONDS=${FUZZ_SECONDS:-5}
CLI=${VS_CLI:-build/volscissors}
ALL="nifti niftigz nrrd nhdr meta vtk vti png tiff dicom ply obj stl meshvtk treevtk swc treejson polylinesjson pngimage
     contour report overlayjson overlayvtk targetsjson targetstxt zarr"
TARGETS=${FUZZ_TARGETS:-$ALL}
CCACHE=$(command -v ccache >/dev/null && echo "-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache" || true)

if [ "${FUZZ_SEEDS_ONLY:-0}" = 1 ]; then
  : # the seeds need only the Release CLI
elif [ ! -f "$FUZZ_BUILD/CMakeCache.txt" ]; then
  CC=clang CXX=clang++ cmake -S . -B "$FUZZ_BUILD" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVS_FUZZ=ON \
    -DVS_BUILD_TESTS=OFF -DVS_BUILD_BENCH=OFF $CCACHE > "$FUZZ_BUILD.configure.log" 2>&1 ||
    { cat "$FUZZ_BUILD.configure.log"; exit 1; }
fi
[ "${FUZZ_SEEDS_ONLY:-0}" = 1 ] || cmake --build "$FUZZ_BUILD" -j "${JOBS:-2}" --target $(for t in $TARGETS; do printf 'fuzz_%s ' "$t"; done) -- --no-print-directory
[ -x "$CLI" ] || { echo "fuzz: $CLI not built (run make build first)" >&2; exit 1; }

# ---------------------------------------------------------------- seed corpus
SEEDS="$FUZZ_BUILD/fuzz-seeds"
rm -rf "$SEEDS" && mkdir -p "$SEEDS"
gen="$SEEDS/gen"
mkdir -p "$gen"
"$CLI" -q phantom vessels --size 32,28,24 --seed 3 --out "$gen/v.nii" --truth "$gen/truth.json"
for ext in nii.gz nrrd nhdr mha mhd; do "$CLI" -q convert "$gen/v.nii" "$gen/v.$ext"; done
"$CLI" -q render "$gen/v.nii" --mode slice --size 24x20 --out "$gen/s.png" || true
"$CLI" -q trace "$gen/v.nii" --targets-file "$gen/truth.json" --out "$gen/tree.swc" || true
"$CLI" -q trace "$gen/v.nii" --targets-file "$gen/truth.json" --out "$gen/tree.json" --vtk "$gen/lines.vtk" \
  --json "$gen/report.json" || true
"$CLI" -q livewire "$gen/v.nii" --slice z=12 --points "4,4;20,6;14,20" --closed --out "$gen/contour.json" || true
/usr/bin/python3 - "$gen" <<'PY'
import struct, sys, zlib, base64
d = sys.argv[1]
def w(name, data):
    open(f"{d}/{name}", "wb").write(data if isinstance(data, bytes) else data.encode())
w("a.vtk", "# vtk DataFile Version 3.0\nseed\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 3 2 2\nSPACING 1 1 2\n"
           "ORIGIN 0 0 0\nPOINT_DATA 12\nSCALARS s unsigned_char 1\nLOOKUP_TABLE default\n0 1 2 3 4 5 6 7 8 9 10 11\n")
vals = struct.pack(">12h", *range(-6, 6))
w("b.vtk", b"# vtk DataFile Version 3.0\nseed\nBINARY\nDATASET STRUCTURED_POINTS\nDIMENSIONS 3 2 2\n"
           b"POINT_DATA 12\nSCALARS s short 1\nLOOKUP_TABLE default\n" + vals + b"\nVECTORS v float\n" + bytes(144))
raw = bytes(range(12))
z = zlib.compress(raw)
hdr = struct.pack("<4I", 1, 12, 12, len(z))
w("a.vti", b'<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian" header_type="UInt32" '
           b'compressor="vtkZLibDataCompressor">\n<ImageData WholeExtent="0 2 0 1 0 1" Origin="0 0 0" Spacing="1 1 1">\n'
           b'<Piece Extent="0 2 0 1 0 1"><PointData Scalars="s">\n<DataArray type="UInt8" Name="s" format="appended" offset="0"/>\n'
           b'</PointData></Piece></ImageData>\n<AppendedData encoding="raw">\n_' + hdr + z + b"\n</AppendedData>\n</VTKFile>\n")
w("b.vti", '<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian">\n<ImageData WholeExtent="0 2 0 1 0 1" '
           'Spacing="1 1 1"><Piece Extent="0 2 0 1 0 1"><PointData Scalars="s"><DataArray type="Float32" Name="s" '
           'format="binary">' + base64.b64encode(struct.pack("<I12f", 48, *[i * 0.5 for i in range(12)])).decode() +
           '</DataArray></PointData></Piece></ImageData></VTKFile>\n')
w("p.nhdr", "NRRD0004\ndimension: 3\nsizes: 2 2 2\ntype: uchar\nencoding: raw\ndata file: sl%03d.raw 1 2 1\n")
w("p.mhd", "ObjectType = Image\nNDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\nElementDataFile = sl%03d.raw 1 2 1\n")
# Minimal baseline TIFF, 4x3 8-bit grey, one strip.
ifd = [(256, 3, 1, 4), (257, 3, 1, 3), (258, 3, 1, 8), (259, 3, 1, 1), (262, 3, 1, 1), (273, 4, 1, 8),
       (277, 3, 1, 1), (278, 3, 1, 3), (279, 4, 1, 12)]
t = b"II*\0" + struct.pack("<I", 20) + bytes(range(12))
t += struct.pack("<H", len(ifd)) + b"".join(struct.pack("<HHII", *e) for e in ifd) + struct.pack("<I", 0)
w("a.tif", t)
w("a.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
           "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
w("b.ply", b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
           b"element face 1\nproperty list uchar int vertex_indices\nend_header\n" + struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
           + struct.pack("<B3i", 3, 0, 1, 2))
w("a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n")
w("a.stl", "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n")
w("b.stl", bytes(80) + struct.pack("<I", 1) + struct.pack("<12fH", 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0))
w("m.vtk", "# vtk DataFile Version 3.0\nm\nASCII\nDATASET POLYDATA\nPOINTS 3 float\n0 0 0 1 0 0 0 1 0\nPOLYGONS 1 4\n3 0 1 2\n"
           "POINT_DATA 3\nSCALARS s float 1\nLOOKUP_TABLE default\n1 2 3\nNORMALS n float\n0 0 1 0 0 1 0 0 1\n")
w("tree.vtk", "# vtk DataFile Version 3.0\ntree\nASCII\nDATASET POLYDATA\nPOINTS 4 double\n0 0 0 1 0 0 1 1 0 2 0 1\n"
              "LINES 3 9\n2 0 1\n2 1 2\n2 1 3\nPOINT_DATA 4\nSCALARS radius double 1\nLOOKUP_TABLE default\n"
              "2 1.5 1 0.5\nFIELD FieldData 1\ntype 1 4 int\n1 3 3 3\n")
w("uv.json", '{"points": [[1.5, 2], [10, 12], [3, 20]], "slice": {"axis": "y", "index": 7}}')
w("pl.json", '{"polylines": [{"points": [[0, 0, 0], [1, 2, 3]], "radii": [1, 2]}]}')
w("t.txt", "# root first\n3 4 5\n6,7,8\n")
w("t.json", '{"root": [1, 2, 3], "targets": [[4, 5, 6], {"voxel": [7, 8, 9]}]}')
PY
dicom=$(find ../shared/data -iname '*.dcm' -size -300k 2>/dev/null | head -1 || true)

seed() {  # seed TARGET FILE...
  local target=$1
  shift
  mkdir -p "$SEEDS/$target"
  for f in "$@"; do if [ -f "$f" ]; then cp "$f" "$SEEDS/$target/"; fi; done
}
seed nifti "$gen/v.nii"; seed niftigz "$gen/v.nii.gz"; seed nrrd "$gen/v.nrrd"; seed nhdr "$gen/v.nhdr" "$gen/p.nhdr"
seed meta "$gen/v.mha" "$gen/v.mhd" "$gen/p.mhd"; seed vtk "$gen/a.vtk" "$gen/b.vtk"; seed vti "$gen/a.vti" "$gen/b.vti"
seed png "$gen/s.png"; seed pngimage "$gen/s.png"; seed tiff "$gen/a.tif"; seed dicom ${dicom:+"$dicom"}
seed ply "$gen/a.ply" "$gen/b.ply"; seed obj "$gen/a.obj"; seed stl "$gen/a.stl" "$gen/b.stl"; seed meshvtk "$gen/m.vtk" "$gen/lines.vtk"; seed treevtk "$gen/tree.vtk" "$gen/lines.vtk"
seed swc "$gen/tree.swc"; seed treejson "$gen/tree.json"; seed polylinesjson "$gen/pl.json"
seed contour "$gen/contour.json"; seed report "$gen/report.json"
seed overlayjson "$gen/report.json" "$gen/contour.json" "$gen/uv.json" "$gen/pl.json" "$gen/tree.json"
seed overlayvtk "$gen/lines.vtk" "$gen/m.vtk"
seed targetsjson "$gen/t.json" "$gen/truth.json"; seed targetstxt "$gen/t.txt"
# OME-Zarr: level 0's .zarray, a NUL, its one chunk (zlib), as fuzz_reader.cpp's "zarr" reader expects.
"$CLI" -q convert "$gen/v.nii" "$gen/v.zarr" && { cat "$gen/v.zarr/0/.zarray"; printf '\0'; cat "$gen/v.zarr/0/0.0.0"; } > "$gen/z.bin"
seed zarr "$gen/z.bin"

# FUZZ_SEEDS_ONLY=1: only the seed corpus (scripts/asan-readers.sh replays it without libFuzzer).
[ "${FUZZ_SEEDS_ONLY:-0}" = 1 ] && exit 0

# ---------------------------------------------------------------- run
CRASHES="$FUZZ_BUILD/fuzz-crashes"
mkdir -p "$CRASHES"
failed=0
total_runs=0
for t in $TARGETS; do
  corpus="$FUZZ_BUILD/fuzz-corpus/$t"
  mkdir -p "$corpus" "$CRASHES/$t"
  log="$FUZZ_BUILD/fuzz-$t.log"
  if ASAN_OPTIONS=detect_leaks=0:allocator_may_return_null=1 "$FUZZ_BUILD/fuzz/fuzz_$t" -max_total_time="$FUZZ_SECONDS" \
      -max_len=8192 -timeout=10 -rss_limit_mb=3072 -print_final_stats=1 -artifact_prefix="$CRASHES/$t/" \
      "$corpus" "$SEEDS/$t" > "$log" 2>&1; then
    status=ok
  else
    status=FOUND
    failed=1
  fi
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
  total_runs=$((total_runs + ${runs:-0}))
  printf 'fuzz %-14s %8s runs  %s\n' "$t" "${runs:-0}" "$status"
  [ "$status" = ok ] || grep -m3 -E 'ERROR|SUMMARY|deadly|timeout' "$log" | sed 's/^/    /'
done
echo "fuzz: $total_runs inputs in total, ${FUZZ_SECONDS}s per target; $( [ $failed = 0 ] && echo 'no crash' || echo "CRASHES in $CRASHES")"
exit $failed
