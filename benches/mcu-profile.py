#!/usr/bin/env python3
"""Where a firmware's instructions go, by pipeline stage (the keys name src/pipeline/ files and functions).

Usage: mcu-profile.py ELF1 PROF1 ELF2 PROF2 COVERED [WRITTEN RUNS DRAWN]
  ELFn/PROFn: the firmware rendering n frames and its per-address instruction counts
  (benches/qemu-pcprof); COVERED: covered pixels per frame; WRITTEN, RUNS, DRAWN: the frame's
  pixels written, runs of pixels and triangles drawn (the firmware's JSON line), for the
  per-unit figures (pixel loop per written pixel, rows and spans per run, set-up plus front end
  per drawn triangle).
Prints a markdown table of instructions per frame (2 frames - 1 frame) per stage. Each
executed address is attributed, through its inlining chain (llvm-addr2line), to the first
stage below whose function appears in the chain.
"""
import collections
import json
import subprocess
import sys

STAGES = [
    ("pixel loop (depth test, texel, light, store)", ["SpanSink", "Shader$LT$C$C$D$C$B$C$Lt$C$_$GT$::run", "fragment::lit_fragment"]),
    ("rows and spans (edges, plane or exact varyings per run)", ["for_each_span", "raster::Setup<_>::emit", "WalkedRows", "draw_rows", "linear_row", "exact_row",
                                                                 "PixelRows", "RowCursor", "draw_pixel_rows"]),
    ("triangle set-up (edges, depth plane, affine test)", ["Setup", "raster::facing", "AffinePlanes"]),
    ("lighting per vertex", ["Lights", "sqrtf"]),
    ("clipping and projection", ["clip_triangle", "clip::classify", "clip::cut", "draw_clipped", "project",
                                 "clip::outcode", "Projected"]),
    # Before the front end, whose "fill" keys would take the band clear's block fill (inlined
    # into the caller's `Band::clear`).
    ("band clear", ["Band$LT$C$C$D$GT$::clear", "memset", "memclr"]),
    ("vertex fetch, transform, culling, fan-out", ["pipeline::primitive", "pipeline::vertex", "fragment::fill",
                                                     "format::mesh", "pipeline::scratch", "pipeline::draw_mesh_with",
                                                     "pipeline::draw_all", "Renderer", "fill"]),
    ("memcpy", ["memcpy"]),
]


def stages(elf, prof):
    rows = [line.split() for line in open(prof)]
    out = subprocess.run(["llvm-addr2line", "--output-style=JSON", "-f", "-i", "-C", "-e", elf],
                         input="\n".join("0x" + r[0] for r in rows) + "\n",
                         capture_output=True, text=True, check=True).stdout.strip().split("\n")
    total = collections.Counter()
    for line, (_, count) in zip(out, rows):
        names = " | ".join(f["FunctionName"] for f in json.loads(line)["Symbol"])
        stage = next((s for s, keys in STAGES if any(k in names for k in keys)), "other (start-up, firmware, soft-float helpers)")
        total[stage] += int(count)
    return total


def main():
    elf1, prof1, elf2, prof2, covered = sys.argv[1:6]
    one, two = stages(elf1, prof1), stages(elf2, prof2)
    covered = int(covered)
    print("| stage | insns per frame | per covered pixel |")
    print("| --- | ---: | ---: |")
    total = 0
    # Reported in pipeline order (the band clear after the front end, as before).
    names = [s for s, _ in STAGES if s != "band clear"]
    names.insert(names.index("memcpy"), "band clear")
    for stage in names + ["other (start-up, firmware, soft-float helpers)"]:
        per_frame = two[stage] - one[stage]
        total += per_frame
        print(f"| {stage} | {per_frame} | {per_frame / covered:.1f} |")
    print(f"| total | {total} | {total / covered:.1f} |")
    if len(sys.argv) >= 9:
        written, runs, drawn = (int(a) for a in sys.argv[6:9])
        per = lambda stage: two[stage] - one[stage]
        front = sum(per(s) for s, _ in STAGES if s.split()[0] in ("triangle", "lighting", "clipping", "vertex"))
        print()
        print("| figure | instructions |")
        print("| --- | ---: |")
        print(f"| pixel loop per written pixel ({written} written) | {per(STAGES[0][0]) / written:.1f} |")
        print(f"| rows and spans per run ({runs} runs) | {per(STAGES[1][0]) / runs:.1f} |")
        print(f"| set-up, lighting, clipping and front end per drawn triangle ({drawn} drawn) | {front / drawn:.1f} |")


if __name__ == "__main__":
    main()
