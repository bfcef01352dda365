#!/usr/bin/env python3
"""Where a firmware's stack goes: the frame of every function a frame runs, and the layout of one.

    benches/profile.sh --features stack-probe --keep DIR      # a stack-probe build, kept
    python3 benches/stack-frames.py DIR [MIN_BYTES]            # frames of the functions run
    python3 benches/stack-frames.py DIR --layout FUNCTION      # one function's frame, by variable

The first form lists, largest first, the frame size (the prologue's pushes and `sub sp`) of every
function of DIR/fw-1.elf whose code ran (DIR/pc-1.txt, the per-address counts), with how often it
was entered: the core stack that `benches/mcu.sh` measures is one chain of these. The second form
prints, for the first function whose name contains FUNCTION, every variable that DWARF places at
`SP + N` (`llvm-dwarfdump --debug-info`), with the inlined calls it belongs to (innermost first):
what occupies the frame, slot by slot. Needs llvm-objdump and llvm-dwarfdump.
"""
import re
import subprocess
import sys

PUSH = re.compile(r"\t(push|stmdb|vpush)(?:\.w)?\s+(?:sp!,\s*)?\{([^}]*)\}")
SUB_SP = re.compile(r"\tsub(?:\.w)?\s+sp,\s*(?:sp,\s*)?#(0x[0-9a-f]+|\d+)")


def pushed_bytes(match):
    regs = [r.strip() for r in match.group(2).split(",")]
    count = 0
    for r in regs:
        if "-" in r:
            a, b = r.split("-")
            count += int(b[1:]) - int(a[1:]) + 1
        else:
            count += 1
    return count * (8 if match.group(1) == "vpush" and regs[0].startswith("d") else 4)


def frames(elf, counts):
    """{function: (frame bytes, times entered, ran)} from the listing's prologues."""
    listing = subprocess.run(["llvm-objdump", "-d", "--no-show-raw-insn", "-C", elf],
                             capture_output=True, text=True, check=True).stdout
    result, name, seen = {}, None, 0
    for line in listing.splitlines():
        head = re.match(r"^([0-9a-f]+) <(.*)>:", line)
        if head:
            name, seen = head.group(2), 0
            result[name] = [0, counts.get(int(head.group(1), 16), 0), False]
            continue
        if name is None:
            continue
        at = re.match(r"^\s*([0-9a-f]+):", line)
        if at and int(at.group(1), 16) in counts:
            result[name][2] = True
        seen += 1
        if seen <= 14:
            push, sub = PUSH.search(line), SUB_SP.search(line)
            if push:
                result[name][0] += pushed_bytes(push)
            if sub:
                result[name][0] += int(sub.group(1), 0)
    return result


def demangle(symbol):
    """A legacy Rust symbol's path, short: `_ZN6soft3d4math3mul17h...E` -> `math::mul`."""
    if not symbol.startswith("_ZN"):
        return symbol
    parts, rest = [], symbol[3:]
    while rest and rest[0].isdigit():
        digits = re.match(r"\d+", rest).group(0)
        n = int(digits)
        parts.append(rest[len(digits):len(digits) + n])
        rest = rest[len(digits) + n:]
    if parts and re.fullmatch(r"h[0-9a-f]{16}", parts[-1]):
        parts.pop()
    for code, text in (("$LT$", "<"), ("$GT$", ">"), ("$u20$", " "), ("$C$", ","), ("$RF$", "&"), ("..", "::")):
        parts = [p.replace(code, text) for p in parts]
    return "::".join(parts[-2:])


def layout(elf, function):
    """Every variable on SP + N in `function`'s DWARF, with its inlined calls."""
    nm = subprocess.run(["llvm-nm", "-C", elf], capture_output=True, text=True, check=True).stdout
    address = next((l.split()[0] for l in nm.splitlines() if function in l), None)
    if address is None:
        sys.exit(f"stack-frames: no symbol contains {function}")
    low = "0x%08x" % (int(address, 16) & ~1)
    lines = subprocess.run(["llvm-dwarfdump", "--debug-info", elf],
                           capture_output=True, text=True, check=True).stdout.split("\n")
    names, die = {}, None
    for l in lines:
        m = re.match(r"^(0x[0-9a-f]+):\s+DW_TAG_", l)
        if m:
            die = m.group(1)
            continue
        m = re.search(r'DW_AT_name\s+\("(.*)"\)', l)
        if m and die and die not in names:
            names[die] = m.group(1)
    start = next(i for i, l in enumerate(lines) if f"DW_AT_low_pc\t({low})" in l)
    top = len(re.match(r"^0x[0-9a-f]+:(\s+)", lines[start - 1]).group(1))
    stack, found, entry = [], [], None
    for l in lines[start + 1:]:
        m = re.match(r"^(0x[0-9a-f]+):(\s+)(DW_TAG_\w+|NULL)", l)
        if m:
            depth = len(m.group(2))
            if depth <= top and m.group(3) != "NULL":
                break
            while stack and stack[-1][0] >= depth:
                stack.pop()
            entry = {"tag": m.group(3)}
            stack.append((depth, entry))
            if m.group(3) in ("DW_TAG_variable", "DW_TAG_formal_parameter"):
                found.append((entry, [e for _, e in stack[:-1] if e["tag"] == "DW_TAG_inlined_subroutine"]))
        elif entry is not None:
            for key in ("name", "location", "abstract_origin"):
                mm = re.search(r"DW_AT_%s\s+\((.*)\)" % key, l)
                if mm:
                    entry[key] = mm.group(1)

    def label(e):
        if "name" in e:
            return e["name"].strip('"')
        m = re.match(r'(0x[0-9a-f]+)(?: "(.*)")?', e.get("abstract_origin", ""))
        return demangle(m.group(2) or names.get(m.group(1), "?")) if m else "?"

    rows = set()
    for e, chain in found:
        m = re.match(r"DW_OP_breg13 SP\+(\d+)", e.get("location", ""))
        if m:
            rows.add((int(m.group(1)), label(e), " < ".join(label(c) for c in reversed(chain))[:150]))
    for offset, name, chain in sorted(rows):
        print(f"{offset:6d}  {name:20s}  {chain}")


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    work = sys.argv[1]
    if len(sys.argv) >= 4 and sys.argv[2] == "--layout":
        layout(f"{work}/fw-1.elf", sys.argv[3])
        return
    minimum = int(sys.argv[2]) if len(sys.argv) >= 3 else 64
    counts = {}
    for l in open(f"{work}/pc-1.txt"):
        address, count = l.split()[:2]
        counts[int(address, 16)] = int(count)
    table = frames(f"{work}/fw-1.elf", counts)
    print("frame bytes  entered  function")
    for name, (size, entered, ran) in sorted(table.items(), key=lambda kv: -kv[1][0]):
        if ran and size >= minimum:
            print(f"{size:11d}  {entered:7d}  {name[:120]}")


if __name__ == "__main__":
    main()
