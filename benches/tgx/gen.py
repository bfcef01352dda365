#!/usr/bin/env python3
"""Writes the TGX firmware's model and texture headers for soft3d's reference Suzanne frame.

  gen.py BABYLON S3D TGX_SRC OUT_DIR   -> OUT_DIR/suzanne.obj, suzanne.h (Mesh3D), suzanne_texture.h

Geometry: BABYLON (assets/suzanne/monkey.babylon: legacy interleaved layout, stride 8:
x y z nx ny nz u v; 886 vertices, 966 triangles). Babylon is left-handed, TGX right-handed
(OpenGL): the scene is mirrored in z (positions and normals z -> -z; the firmware mirrors the
camera, the light and the model rotation the same way), which leaves the picture and the
on-screen winding unchanged. UVs are written as stored: TGX reads texel row floor(v * H) from
the top of the image, which is the v = 0-at-the-top origin that this file needs.

Triangle order / strips: TGX's own (legacy, pure-Python) OBJ converter
TGX_SRC/tools/legacy_tools/obj_to_h.py is run on the OBJ written here (answers fed on stdin: no
recentring, model name "suzanne", default material, texture "suzanne"); it chains the triangles
into TGX's strip format and writes OUT_DIR/suzanne.h. The firmware ignores the header's material
(drawMesh(..., use_mesh_material = false)) and sets its own.

Texture: the 128x128 RGB565 texels of S3D, the output of soft3d's converter with the QEMU
firmware's options (run.sh makes it), so that both renderers sample the same texels; .s3d stores
row 0 at the bottom, TGX at the top: rows are flipped.
"""
import json, os, struct, subprocess, sys

if len(sys.argv) != 5:
    sys.exit(__doc__)
BABYLON, S3D, TGX_SRC, OUT = (os.path.abspath(a) for a in sys.argv[1:])


def write_obj(path):
    d = json.load(open(BABYLON))
    m = d["meshes"][0]
    v, idx = m["vertices"], m["indices"]
    stride = 6 + 2 * m["uvCount"]
    n = len(v) // stride
    with open(path, "w") as f:
        f.write("o suzanne\n")
        for i in range(n):
            x, y, z = v[i * stride:i * stride + 3]
            f.write(f"v {x!r} {y!r} {-z!r}\n")
        for i in range(n):
            u, t = v[i * stride + 6:i * stride + 8]
            f.write(f"vt {u!r} {t!r}\n")
        for i in range(n):
            nx, ny, nz = v[i * stride + 3:i * stride + 6]
            f.write(f"vn {nx!r} {ny!r} {-nz!r}\n")
        for k in range(0, len(idx), 3):
            a, b, c = (j + 1 for j in idx[k:k + 3])
            f.write(f"f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}\n")
    return n, len(idx) // 3, m["position"]


def run_tgx_converter():
    tool = os.path.join(TGX_SRC, "tools", "legacy_tools", "obj_to_h.py")
    # questions: obj file, resize (n), model name, default colour/lighting (Y), texture name
    answers = "suzanne.obj\nn\nsuzanne\nY\nsuzanne\n"
    r = subprocess.run([sys.executable, tool], input=answers, cwd=OUT, capture_output=True, text=True)
    if r.returncode != 0 or not os.path.exists(os.path.join(OUT, "suzanne.h")):
        sys.exit("obj_to_h.py failed:\n" + r.stdout + r.stderr)
    return r.stdout


def write_texture(path):
    b = open(S3D, "rb").read()
    assert b[:4] == b"S3D\0"
    tex_count = struct.unpack_from("<H", b, 16)[0]
    tex_table = struct.unpack_from("<I", b, 32)[0]
    assert tex_count == 1
    w, h = struct.unpack_from("<HH", b, tex_table)
    fmt = b[tex_table + 4]
    off = struct.unpack_from("<I", b, tex_table + 8)[0]
    texels = struct.unpack_from(f"<{w * h}H", b, off)
    rows = [texels[j * w:(j + 1) * w] for j in range(h)][::-1]  # bottom-first -> top-first
    with open(path, "w") as f:
        f.write(f"// Suzanne.jpg as {w}x{h} RGB565 (soft3d's converter output, format code {fmt}), top row first.\n")
        f.write("#pragma once\n#include <tgx.h>\n\n")
        f.write(f"const uint16_t suzanne_texture_data[{w * h}] __attribute__((aligned(4))) = {{\n")
        for r in rows:
            f.write(",".join(str(t) for t in r) + ",\n")
        f.write("};\n")
        f.write(f"const tgx::Image<tgx::RGB565> suzanne_texture((void*)suzanne_texture_data, {w}, {h});\n")
    return w, h, fmt


def main():
    os.makedirs(OUT, exist_ok=True)
    nv, nt, pos = write_obj(os.path.join(OUT, "suzanne.obj"))
    print(f"suzanne.obj: {nv} vertices, {nt} triangles, mesh position {pos}")
    log = run_tgx_converter()
    for line in log.splitlines():
        if "chains" in line or "triangles" in line:
            print("obj_to_h.py:", line.strip())
    print("texture:", write_texture(os.path.join(OUT, "suzanne_texture.h")))


if __name__ == "__main__":
    main()
