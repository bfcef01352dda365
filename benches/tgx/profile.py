#!/usr/bin/env python3
"""Per-frame instruction profile of the TGX firmware: per-address counts of the 2-frame run minus
those of the 1-frame run (same code: fw/Makefile), attributed through llvm-addr2line -f -i.

  profile.py ELF PC1 PC2 [--lines FILE_SUBSTRING] [--addr LO HI]

Prints: the frame total; by outermost function; by innermost (inlined) function; by stage (see
stage_of: source-line ranges of TGX's headers at commit d43f889); and with --lines, the per-
frame count of each source line of the files whose name contains FILE_SUBSTRING (innermost
frame in that file); with --addr, each executed instruction between LO and HI (hex) with its
per-frame count and disassembly.
"""
import collections, json, re, subprocess, sys

def load(path):
    d = {}
    for line in open(path):
        a, c = line.split()
        d[int(a, 16)] = int(c)
    return d


def addr2line(elf, addrs):
    out = subprocess.run(["llvm-addr2line", "--output-style=JSON", "-f", "-i", "-C", "-e", elf],
                         input="\n".join(hex(a) for a in addrs) + "\n", capture_output=True, text=True,
                         check=True).stdout.strip().split("\n")
    res = {}
    for a, line in zip(addrs, out):
        res[a] = [(f["FunctionName"], f["FileName"].split("/")[-1], f["Line"]) for f in json.loads(line)["Symbol"]]
    return res


def short(name):
    name = re.sub(r"<tgx::RGB565, \(tgx::Shader\)\d+, unsigned short, 1, 0>", "<..>", name)
    name = re.sub(r"\(.*\)( const)?$", "", name)
    return name[:110]


# Stages. The uber shader (one function, tgx::uber_shader): its pixel loop is found by address
# (the back-branches to the loop head that holds the hottest instruction), the rest by the line
# of uber_shader_inline (< 414: per-triangle set-up, >= 414: per-row). _drawMesh (everything from
# strip decoding to the rasterizer, inlined): by the line of the _drawMesh frame in Renderer3D.inl.
PIXEL_LOOP = (0, -1)


def find_pixel_loop(elf, diff, info):
    addrs = [a for a in diff if any("uber_shader<" in n for n, _, _ in info[a][-1:])]
    lo, hi = min(addrs), max(addrs) + 4
    hottest = max(addrs, key=lambda a: diff[a])
    dis = subprocess.run(["arm-none-eabi-objdump", "-d", "--no-show-raw-insn", f"--start-address={lo:#x}",
                          f"--stop-address={hi:#x}", elf], capture_output=True, text=True).stdout
    back = []
    for line in dis.splitlines():
        m = re.match(r"\s*([0-9a-f]+):\s+(b[a-z.]*)\s+([0-9a-f]+) <", line)
        if m and int(m.group(3), 16) < int(m.group(1), 16):
            back.append((int(m.group(3), 16), int(m.group(1), 16)))
    head = min((t for t, s in back if t <= hottest <= s), key=lambda t: hottest - t)
    return head, max(s for t, s in back if t == head)


def stage_of(chain, addr=None):
    names = " ".join(n for n, _, _ in chain)
    outer = chain[-1][0]
    if "uber_shader<" in outer:
        if addr is not None and PIXEL_LOOP[0] <= addr <= PIXEL_LOOP[1]:
            return "C1 pixel loop (z test, 1/w, texel, modulate, stores, steps)"
        ub = [l for (n, f, l) in chain if "uber_shader_inline" in n and f == "Shaders.h"]
        if ub and ub[0] >= 414:
            return "C2 per row (first pixel by division, varyings at row start, run entry/exit, row step)"
        return "C3 shader per-triangle set-up (gradients of z, 1/w, u/w, v/w, colour; call)"
    if outer == "floorf":
        return "T1 rasterizer per-triangle set-up (snap incl. floorf calls, bbox, edges, top-left)"
    if "_drawMesh" in outer:
        line = next((l for n, f, l in chain if "_drawMesh" in n and f == "Renderer3D.inl"), 0)
        inner = chain[0][0]
        if line == 1992:
            if any(n.startswith("void tgx::shader_select") for n, _, _ in chain):
                return "C3 shader per-triangle set-up (gradients of z, 1/w, u/w, v/w, colour; call)"
            if "rasterizeTriangle" in names or any(f in ("Rasterizer.h", "Misc.h") for _, f, _ in chain):
                return "T1 rasterizer per-triangle set-up (snap incl. floorf calls, bbox, edges, top-left)"
            return "T2 per-triangle: vertex records copied for the rasterizer call"
        if 1868 <= line <= 1894 or 1996 <= line <= 2004:
            if "mult1" in inner:
                return "V1 per-vertex: model-view transform (mult1)"
            return "T3 per-triangle: strip decode, pointers, flags"
        if 1896 <= line <= 1899:
            return "T4 per-triangle: back-face culling (cross, dot)"
        if 1902 <= line <= 1913:
            return "V2 per-vertex: projection (projM * P, 1/w)"
        if 1917 <= line <= 1943:
            return "T5 per-triangle: clip test"
        if 1946 <= line <= 1971:
            if "_powSpecular" in names:
                return "V4 per-vertex: specular term (strength 0, computed anyway)"
            if "mult0" in inner:
                return "V3 per-vertex: normal transform (mult0)"
            return "V3 per-vertex: diffuse lighting (_shadeVertex)"
        if 1979 <= line <= 1989:
            return "T3 per-triangle: strip decode, pointers, flags"
        return "M per-mesh set-up (bbox test, matrices)"
    if "memset" == outer:
        return "F1 clear z-buffer (memset)"
    if "_fillRect" in outer or "fillScreen" in names:
        return "F2 clear colour buffer (fillScreen)"
    return "M per-mesh set-up (bbox test, matrices)" if "Renderer3D" in outer else "other: " + short(outer)


def units(diff, info):
    """Work counts read from the execution counts of particular instructions (exact: each is the
    number of times a given source statement ran in the frame)."""
    def at(pred, how=max):
        v = [diff[a] for a in diff if pred(a, info[a])]
        return how(v) if v else 0
    def line_in(fn_part, fname, lines):
        return lambda a, ch: any(fn_part in n and f == fname and l in lines for n, f, l in ch)
    in_loop = lambda a: PIXEL_LOOP[0] <= a <= PIXEL_LOOP[1]
    u = {}
    u["strip triangles (culling test)"] = at(line_in("_drawMesh", "Renderer3D.inl", {1896, 1897}))
    u["chains (strips)"] = at(line_in("_drawMesh", "Renderer3D.inl", {1872}))
    u["positions transformed (mult1)"] = 3 * u["chains (strips)"] + at(line_in("_drawMesh", "Renderer3D.inl", {1999}))
    u["triangles entering rasterizeTriangle (not culled)"] = at(lambda a, ch: any(f == "Rasterizer.h" for _, f, _ in ch))
    u["vertices projected and lit (lazy, per strip)"] = sum(at(line_in("_drawMesh", "Renderer3D.inl", {l})) for l in (1967, 1953, 1961))
    u["triangles reaching the shader (drawn)"] = at(lambda a, ch: "uber_shader<" in ch[-1][0] and ch[0][1:] == ("Shaders.h", 1564))
    u["row-loop iterations"] = at(line_in("uber_shader_inline", "Shaders.h", {418}))
    u["row starts (first pixel found, varyings evaluated)"] = at(line_in("uber_shader_inline", "Shaders.h", {450}))
    u["runs (rows with >= 1 pixel)"] = at(lambda a, ch: not in_loop(a) and line_in("uber_shader_inline", "Shaders.h", {512})(a, ch), min)
    u["pixels visited (edge test passed)"] = at(lambda a, ch: in_loop(a))
    u["pixels written (z test passed)"] = at(lambda a, ch: in_loop(a) and line_in("uber_shader_inline", "Shaders.h", {730})(a, ch))
    print("| work unit per frame | count |\n|---|---:|")
    for k, v in u.items():
        print(f"| {k} | {v:,} |")
    print()
    return u


def main():
    elf, p1, p2 = sys.argv[1:4]
    a, b = load(p1), load(p2)
    diff = {k: b.get(k, 0) - a.get(k, 0) for k in set(a) | set(b)}
    diff = {k: v for k, v in diff.items() if v}
    total = sum(diff.values())
    info = addr2line(elf, sorted(diff))
    print(f"per-frame instructions (sum of per-address differences): {total:,}\n")
    global PIXEL_LOOP
    PIXEL_LOOP = find_pixel_loop(elf, diff, info)
    print(f"pixel loop: {PIXEL_LOOP[0]:#x}..{PIXEL_LOOP[1]:#x}\n")
    for title, key in (("outermost function", lambda ch, a: short(ch[-1][0])),
                       ("innermost (inlined) function", lambda ch, a: short(ch[0][0])),
                       ("stage", stage_of)):
        c = collections.Counter()
        for k, v in diff.items():
            c[key(info[k], k)] += v
        print(f"| {title} | instructions/frame | share |\n|---|---:|---:|")
        for n, v in (sorted(c.items()) if title == "stage" else c.most_common()):
            if v:
                print(f"| {n} | {v:,} | {100 * v / total:.1f}% |")
        print()
    units(diff, info)
    args = sys.argv[4:]
    if "--lines" in args:
        sub = args[args.index("--lines") + 1]
        c = collections.Counter()
        for k, v in diff.items():
            fr = next(((f, l) for (_, f, l) in info[k] if sub in f), None)
            if fr:
                c[fr] += v
        print(f"| {sub} line | instructions/frame |\n|---|---:|")
        for (f, l), v in sorted(c.items()):
            print(f"| {f}:{l} | {v:,} |")
        print()
    if "--addr" in args:
        lo, hi = (int(x, 16) for x in args[args.index("--addr") + 1:args.index("--addr") + 3])
        dis = subprocess.run(["arm-none-eabi-objdump", "-d", "--no-show-raw-insn", f"--start-address={lo:#x}",
                              f"--stop-address={hi:#x}", elf], capture_output=True, text=True).stdout
        for line in dis.splitlines():
            m = re.match(r"\s*([0-9a-f]+):\s+(.*)", line)
            if m:
                ad = int(m.group(1), 16)
                ch = info.get(ad)
                where = f"{ch[0][1]}:{ch[0][2]}" if ch else ""
                print(f"{diff.get(ad, 0):>9,}  {ad:6x}: {m.group(2):50s} {where}")


if __name__ == "__main__":
    main()
