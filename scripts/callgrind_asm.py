#!/usr/bin/env python3
"""Instructions per ray, instruction by instruction: joins a callgrind profile recorded with
--dump-instr=yes to the disassembly of one function, so that the traversal's set-up, its
loops and its rare paths can be told apart (docs/performance.md, twenty-third round).

    valgrind --tool=callgrind --dump-instr=yes --callgrind-out-file=cg.out \\
      --toggle-collect='*closest_avx2*' target/release/raylab trace MESH --rays R \\
      --accel bvh8 --threads 1 --repeats 1
    scripts/callgrind_asm.py cg.out target/release/raylab closest_avx2 --per 88090 > asm.txt

--per divides every count (the rays traced: `--repeats 1` traces each ray twice, a warm-up
pass and a timed one). The last line sums the instructions executed about once per unit
(set-up and tear-down), more often (loops) and less often (rare paths).
Needs objdump (binutils).
"""
import argparse
import re
import subprocess
import sys
from collections import Counter


def counts_of(profile, function):
    """Instruction address -> events, over the functions whose name matches `function`."""
    names, counts = {}, Counter()
    current, addr, skip = None, 0, False
    for line in open(profile):
        line = line.rstrip("\n")
        m = re.match(r"^(c?fn)=\((\d+)\)(?: (.*))?", line)
        if m:
            if m.group(3):
                names[m.group(2)] = m.group(3)
            if m.group(1) == "fn":
                current = names.get(m.group(2), "")
            continue
        if line.startswith("calls="):
            # The next position line is the call's inclusive cost, not this function's own.
            skip = True
            continue
        if not line or line[0] not in "0123456789+-*":
            continue
        parts = line.split()
        a = parts[0]
        if a.startswith("0x"):
            addr = int(a, 16)
        elif a[0] in "+-":
            step = int(a[1:], 16) if a[1:].startswith("0x") else int(a[1:])
            addr += step if a[0] == "+" else -step
        if skip:
            skip = False
            continue
        if current and re.search(function, current) and len(parts) >= 3:
            counts[addr] += int(parts[2])
    return counts


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("profile", help="callgrind output, recorded with --dump-instr=yes")
    p.add_argument("binary", help="the profiled executable")
    p.add_argument("function", help="regular expression matching the function's name")
    p.add_argument("--per", type=float, default=1.0, help="divide counts by this (rays traced)")
    a = p.parse_args()
    counts = counts_of(a.profile, a.function)
    if not counts:
        sys.exit(f"{a.profile}: no instructions recorded in a function matching '{a.function}'")
    lo, hi = min(counts), max(counts) + 16
    asm = subprocess.run(["objdump", "-d", "--no-show-raw-insn", "-C", f"--start-address={lo:#x}", f"--stop-address={hi:#x}", a.binary], capture_output=True, text=True, check=True).stdout
    once = loops = rare = 0.0
    for line in asm.splitlines():
        m = re.match(r"^\s*([0-9a-f]+):\s*(.*)", line)
        if not m:
            continue
        c = counts.get(int(m.group(1), 16), 0) / a.per
        print(f"{c:9.2f} {m.group(1)} {m.group(2)}")
        if 0.99 <= c <= 1.01:
            once += c
        elif c > 1.01:
            loops += c
        else:
            rare += c
    print(f"# per unit: {once + loops + rare:.1f} instructions; {once:.1f} once (set-up), {loops:.1f} in loops, {rare:.1f} on rarer paths")


if __name__ == "__main__":
    main()
