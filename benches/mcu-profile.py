#!/usr/bin/env python3
"""Where a firmware's instructions go, by pipeline stage (the keys name src/pipeline/ files and functions).

Usage: mcu-profile.py ELF1 PROF1 ELF2 PROF2 COVERED [WRITTEN RUNS DRAWN]
       mcu-profile.py --by-function STAGE DEPTH ELF1 PROF1 ELF2 PROF2
       mcu-profile.py --instructions FUNCTION MIN MAX ELF1 PROF1 ELF2 PROF2
  ELFn/PROFn: the firmware rendering n frames and its per-address instruction counts
  (benches/qemu-pcprof); COVERED: covered pixels per frame; WRITTEN, RUNS, DRAWN: the frame's
  pixels written, runs of pixels and triangles drawn (the firmware's JSON line), for the
  per-unit figures (pixel loop per written pixel, rows and spans per run, set-up plus front end
  per drawn triangle).
Prints a markdown table of instructions per frame (2 frames - 1 frame) per stage. Each
executed address is attributed, through its inlining chain (llvm-addr2line), to the first
stage below whose function appears in the chain.
With --by-function: the instructions per frame of the stages whose name contains STAGE ("" for
all), by the function at DEPTH of each address's inlining chain (0: the innermost, inlined
one; -1: the outermost, the function the code lies in), largest first: where a stage's count
goes.
With --instructions: every instruction of the functions (symbols) whose name contains FUNCTION
("" for all) run between MIN and MAX - 1 times a frame, in address order, with its source line,
then a summary by kind (loads, stores, other): what runs once a triangle (MIN..MAX around the
drawn triangles), once a run, once a pixel. The two builds lay code out at different addresses
and order a function's monomorphised copies differently, so an instruction is matched by its
symbol (without the hash), the digest of that copy's code (addresses left out) and its offset.
"""
import collections
import hashlib
import json
import re
import subprocess
import sys

STAGES = [
    ("pixel loop (depth test, texel, light, store)", ["SpanSink", "Shader$LT$C$C$D$C$B$C$Lt$C$_$GT$::run", "fragment::lit_fragment"]),
    ("rows and spans (edges, plane or exact varyings per run)", ["for_each_span", "row_spans", "raster::runs", "raster::Setup<_>::emit", "WalkedRows", "draw_rows", "linear_row", "exact_row",
                                                                 "PixelRows", "RowCursor", "draw_pixel_rows", "draw_affine_rows"]),
    ("triangle set-up (edges, depth plane, affine test)", ["Setup", "SmallTriangle", "raster::facing", "AffinePlanes"]),
    ("lighting per vertex", ["Lights", "light::sum_lights", "OneFixedLight", "sqrtf"]),
    ("clipping and projection", ["clip_triangle", "clip::classify", "clip::cut", "draw_clipped", "project",
                                 "clip::outcode", "Projected"]),
    # Animation (issue 17): before the front end, which inlines the deformation into its
    # vertex reads.
    # Skinning first: it reads the skin's records (format::animation) in its vertex reads.
    ("skinning and morphing per vertex", ["format::deform"]),
    ("pose evaluation (keys, node and bone matrices)", ["soft3d::animation", "format::animation"]),
    # Before the front end, whose "fill" keys would take the band clear's block fill (inlined
    # into the caller's `Band::clear`).
    ("band clear", ["Band$LT$C$C$D$GT$::clear", "memset", "memclr"]),
    ("vertex fetch, transform, culling, fan-out", ["pipeline::primitive", "pipeline::vertex", "fragment::fill",
                                                     "format::mesh", "pipeline::scratch", "pipeline::draw_mesh_with",
                                                     "pipeline::transform_and_draw", "pipeline::setup",
                                                     "pipeline::draw_all", "Renderer", "fill"]),
    ("memcpy", ["memcpy"]),
]


OTHER = "other (start-up, firmware, soft-float helpers)"


def chains(elf, prof):
    """(inlining chain innermost first, stage, count) of every executed address."""
    rows = [line.split() for line in open(prof)]
    out = subprocess.run(["llvm-addr2line", "--output-style=JSON", "-f", "-i", "-C", "-e", elf],
                         input="\n".join("0x" + r[0] for r in rows) + "\n",
                         capture_output=True, text=True, check=True).stdout.strip().split("\n")
    for line, (_, count) in zip(out, rows):
        frames = [f["FunctionName"] for f in json.loads(line)["Symbol"]]
        names = " | ".join(frames)
        stage = next((s for s, keys in STAGES if any(k in names for k in keys)), OTHER)
        yield frames, stage, int(count)


def stages(elf, prof):
    total = collections.Counter()
    for _, stage, count in chains(elf, prof):
        total[stage] += count
    return total


def by_function(elf, prof, stage_part, depth):
    """Counts of the stages named with `stage_part` by the function at `depth` of the chain
    (without the symbol hash, so that two builds' names match)."""
    total = collections.Counter()
    for frames, stage, count in chains(elf, prof):
        if stage_part in stage:
            name = frames[max(0, min(depth if depth >= 0 else len(frames) + depth, len(frames) - 1))]
            total[re.sub(r"::h[0-9a-f]{16}$", "", name)] += count
    return total


def symbol_offsets(elf, prof):
    """{(symbol without hash, digest of its code, rank, offset): (count, address, instruction)} of
    every executed address of `elf` (the named symbol at or before it, not a mapping symbol such
    as `$t`). Monomorphised copies share a name without the hash, and the two builds may order
    them differently: the digest of a copy's instructions (addresses left out) tells them apart,
    and the rank among copies of equal code (in address order) what is left."""
    counts = {int(a, 16): int(c) for a, c in (line.split() for line in open(prof))}
    text = subprocess.run(["llvm-objdump", "-d", "--no-show-raw-insn", elf], capture_output=True, text=True,
                          check=True).stdout
    symbols, current = [], None
    for line in text.splitlines():
        head = re.match(r"([0-9a-f]+) <(.*)>:", line)
        if head:
            if not head.group(2).startswith("$"):
                current = (re.sub(r"17h[0-9a-f]{16}E$", "", head.group(2)), int(head.group(1), 16), [])
                symbols.append(current)
            continue
        insn = re.match(r"\s*([0-9a-f]+):\s+(.*)", line)
        if insn and current is not None:
            current[2].append((int(insn.group(1), 16), insn.group(2).split("@")[0].strip()))
    out, seen = {}, collections.Counter()
    for name, start, code in symbols:
        # Without addresses: branch targets, and the halves of addresses that `movw`/`movt` build.
        plain = (re.sub(r"0x[0-9a-f]+|<[^>]*>|(?<=^mov[wt])(.*#)\d+", r"\1", i) for _, i in code)
        digest = hashlib.sha1("\n".join(plain).encode()).hexdigest()
        rank = seen[(name, digest)]
        seen[(name, digest)] += 1
        for address, insn in code:
            if address in counts:
                out[(name, digest, rank, address - start)] = (counts[address], address, insn)
    return out


def instructions(function, low, high, elf1, prof1, elf2, prof2):
    """Prints the instructions of `function` run `low..high` times a frame (see the usage)."""
    one, two = symbol_offsets(elf1, prof1), symbol_offsets(elf2, prof2)
    rows = []
    for key, (count, address, insn) in two.items():
        per_frame = count - one.get(key, (0,))[0]
        if function in key[0] and low <= per_frame < high:
            rows.append((address, per_frame, insn, f"{key[0]} ({key[1][:8]})"))
    rows.sort()
    lines = subprocess.run(["llvm-addr2line", "--output-style=JSON", "-i", "-e", elf2],
                           input="\n".join(hex(r[0]) for r in rows) + "\n", capture_output=True, text=True,
                           check=True).stdout.strip().split("\n")
    kinds, symbol = collections.Counter(), None
    for (address, per_frame, insn, name), line in zip(rows, lines):
        # The innermost (inlined) frame's file and line.
        frame = (json.loads(line)["Symbol"] or [{}])[0]
        place = f"{frame.get('FileName', '?').rsplit('/', 1)[-1]}:{frame.get('Line', 0)}"
        if name != symbol:
            print(f"--- {name}")
            symbol = name
        print(f"{address:8x} {per_frame:8d}  {insn:44s} {place}")
        op = insn.split()[0]
        kind = "load" if op.startswith(("ldr", "ldm", "vldr", "pop", "vpop")) else \
            "store" if op.startswith(("str", "stm", "vstr", "push", "vpush")) else "other"
        kinds[kind] += per_frame
    print(f"{len(rows)} instructions, {sum(kinds.values())} executions a frame: "
          + ", ".join(f"{k} {v}" for k, v in sorted(kinds.items())))


def main():
    if sys.argv[1] == "--instructions":
        function, low, high = sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
        instructions(function, low, high, *sys.argv[5:9])
        return
    if sys.argv[1] == "--by-function":
        stage_part, depth, elf1, prof1, elf2, prof2 = sys.argv[2:8]
        one, two = by_function(elf1, prof1, stage_part, int(depth)), by_function(elf2, prof2, stage_part, int(depth))
        per_frame = {name: two[name] - one[name] for name in set(one) | set(two)}
        for name, count in sorted(per_frame.items(), key=lambda item: -item[1]):
            if count:
                print(f"{count:9d}  {name}")
        return
    elf1, prof1, elf2, prof2, covered = sys.argv[1:6]
    one, two = stages(elf1, prof1), stages(elf2, prof2)
    covered = int(covered)
    print("| stage | insns per frame | per covered pixel |")
    print("| --- | ---: | ---: |")
    total = 0
    # Reported in pipeline order (the band clear after the front end, as before).
    names = [s for s, _ in STAGES if s != "band clear"]
    names.insert(names.index("memcpy"), "band clear")
    for stage in names + [OTHER]:
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
