"""Write tests/corpus/: small damaged recordings of the project's own making, one per reader
failure of issue 10, each to be read correctly or refused with a message naming the file
(tests/test_c3d.cpp, CorruptCorpus). Standard library only.

usage: /usr/bin/python3 scripts/make_corpus.py SEED_DIR OUT_DIR
SEED_DIR holds `kin2grf make-example --seconds 1` output (example_squat.c3d/.trc/_grf.mot).
"""
import os
import re
import struct
import sys

seed, out = sys.argv[1], sys.argv[2]
os.makedirs(out, exist_ok=True)
c3d = open(os.path.join(seed, "example_squat.c3d"), "rb").read()
trc = open(os.path.join(seed, "example_squat.trc")).read()
mot = open(os.path.join(seed, "example_squat_grf.mot")).read()


def write(name, data):
    mode = "wb" if isinstance(data, bytes) else "w"
    with open(os.path.join(out, name), mode) as f:
        f.write(data)


def patch_param_int16(data, name, index, value):
    """The int16 at `index` of the parameter `name` (1-dimensional or scalar), little-endian."""
    at = data.find(name.encode())
    assert at > 0, name
    p = at + len(name) + 2  # past the name and the offset to the next parameter
    ndims = data[p + 1]
    p += 2 + ndims + 2 * index
    return data[:p] + struct.pack("<h", value) + data[p + 2:]


# C3D: a truncated data section; a frame count no data can hold; a point count (-5 read as an
# unsigned 65531) the data section cannot hold; the header block alone.
write("c3d_truncated.c3d", c3d[: len(c3d) - 3000])
write("c3d_billion_frames.c3d", patch_param_int16(c3d, "ACTUAL_END_FIELD", 1, 0x3F00))
write("c3d_point_used_65531.c3d", patch_param_int16(c3d, "USED", 0, -5))  # the first USED is POINT:USED
write("c3d_header_only.c3d", c3d[:1024])
# TRC: DataRate against the Time column; Frame# 1e300; a repeated label; a row cut short; NaN rate.
lines = trc.split("\n")
rate_line = lines[2].split("\t")
write("trc_rate_mismatch.trc", "\n".join(lines[:2] + ["\t".join([str(float(rate_line[0]) * 10)] + rate_line[1:])] + lines[3:]))
write("trc_frame_1e300.trc", "\n".join(lines[:6] + ["1e300" + lines[6][lines[6].index("\t"):]] + lines[7:]))
write("trc_duplicate_label.trc", "\n".join(lines[:3] + [lines[3].replace("LSHO", "RSHO", 1)] + lines[4:]))
write("trc_cut_row.trc", "\n".join(lines[:7] + [lines[7][: len(lines[7]) // 2]] + lines[8:]))
write("trc_rate_1e300.trc", "\n".join(lines[:2] + ["\t".join(["1e300"] + rate_line[1:])] + lines[3:]))
# MOT: a row count the rows do not have (OpenSim's own examples); a 30 KB label; a huge count.
write("mot_rows_mismatch.mot", mot.replace("nRows=", "nRows=9", 1))
long = "a" * 30000
write("mot_long_label.mot", mot.replace("ground_force_vx", long + "ground_force_vx", 1))
write("mot_huge_columns.mot", re.sub(r"nColumns=\d+", "nColumns=9923372036854775808", mot, count=1))
# JSON: a number beyond double.
write("cop_1e400.json", '{"delta_hs": 1e400, "delta_ho": 0, "delta_mo": 0.1, "delta_to": 1, "s_hs": 0, "s_ho": 0.3, "s_mo": 0.7, "s_to": 1}')
print("wrote", len(os.listdir(out)), "files to", out)
