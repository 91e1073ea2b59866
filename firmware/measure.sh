#!/usr/bin/env bash
# Flash size, stack use and instruction count of every generated function of the reference
# robots, in f32 and f64, on a Cortex-M4F (thumbv7em-none-eabihf), as a Markdown table.
#
#   firmware/measure.sh [ROBOT...]   print the table (default: the five reference robots)
#   firmware/measure.sh --write      also replace the table in firmware/README.md
#
# How (see README.md, "Embedding in firmware"):
# - builds src/bin/measure.rs in release (the firmware profile: opt-level 3, fat LTO) once per
#   robot (a cargo feature each, to keep every LTO build small), which wraps each function in an exported, never-inlined symbol `eomgen_<robot>_<scalar>_<fn>`;
# - flash: from the ELF's symbol table and disassembly (rustup's llvm-tools), the bytes of the
#   wrapper plus every function it reaches through calls, except the shared libm and
#   compiler-builtins routines (sin/cos, soft-float f64 arithmetic, memcpy), which are reported
#   once per scalar type;
# - stack and instructions: runs the ELF under QEMU's mps2-an386 (Cortex-M4), which paints the
#   stack before each call and counts instructions with SysTick under `-icount shift=0`.
#
# Needs: rustup, cargo, python3, qemu-system-arm. Takes a few minutes (the f64 code of the
# larger robots is slow to compile).
set -euo pipefail
cd "$(dirname "$0")"

write=false
robots=()
for arg in "$@"; do
    case "$arg" in
        --write) write=true ;;
        double_pendulum | ur5 | panda | kinova | allegro_right_hand) robots+=("$arg") ;;
        *) echo "usage: $0 [--write] [double_pendulum|ur5|panda|kinova|allegro_right_hand]..." >&2; exit 2 ;;
    esac
done
if [ ${#robots[@]} -eq 0 ]; then
    robots=(double_pendulum ur5 panda kinova allegro_right_hand)
elif $write; then
    echo "$0: --write needs all robots" >&2; exit 2
fi

target=thumbv7em-none-eabihf
rustup target list --installed | grep -qx "$target" || rustup target add "$target"
rustup component list --installed | grep -q '^llvm-tools' || rustup component add llvm-tools
command -v qemu-system-arm >/dev/null || { echo "qemu-system-arm is missing (Debian: qemu-system-arm)" >&2; exit 1; }

tools="$(rustc --print sysroot)/lib/rustlib/$(rustc -vV | sed -n 's/^host: //p')/bin"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cargo build --release --bin eomgen-firmware >&2
"$tools/llvm-size" -A "target/$target/release/eomgen-firmware" > "$work/firmware-size.txt"
for robot in "${robots[@]}"; do
    echo "measure.sh: $robot" >&2
    cargo build --release --features "$robot" --bin measure >&2
    elf="target/$target/release/measure"
    "$tools/llvm-nm" --print-size --radix=d --defined-only -C "$elf" > "$work/$robot.nm"
    "$tools/llvm-objdump" -d --no-show-raw-insn "$elf" > "$work/$robot.s"
    # A run takes seconds; the timeout only guards against a hang.
    timeout 600 qemu-system-arm -machine mps2-an386 -cpu cortex-m4 -nographic -monitor none \
        -serial none -icount shift=0 -semihosting-config enable=on,target=native \
        -kernel "$elf" > "$work/$robot.run"
done
# Which generated code was measured.
revision="$(git rev-parse --short HEAD 2>/dev/null || echo unknown)"
git diff --quiet HEAD -- ../generated/src ../runtime/src 2>/dev/null || revision="$revision + local changes"

python3 - "$work" "$revision" "${robots[@]}" > "$work/table.md" <<'EOF'
import re, sys
from collections import defaultdict

work, revision, robots = sys.argv[1], sys.argv[2], sys.argv[3:]
JOINTS = {"double_pendulum": 2, "ur5": 6, "panda": 9, "kinova": 6, "allegro_right_hand": 16}
FUNCTIONS = ["mass_matrix", "gravity", "bias", "coriolis_matrix", "inverse_dynamics",
             "forward_dynamics", "kinetic_energy", "potential_energy", "centrifugal",
             "coriolis_pairs", "link_pose", "link_jacobian"]
SCALARS = ("f32", "f64")


def shared(name):
    """libm and compiler-builtins: shared by all functions, so counted once per scalar type."""
    return (name.startswith(("libm::", "compiler_builtins::", "core::", "__"))
            or name in ("memcpy", "memset", "memmove", "memclr", "memcmp", "bcmp"))


def kib(n):
    return f"{n / 1024:.1f} KiB" if n >= 1024 else f"{n} B"


own = {}  # (robot, scalar, function) -> {address: size} of the code it needs, shared excluded
shared_used = {t: {} for t in SCALARS}  # scalar -> {name: size}
measured = {}
for robot in robots:
    # Symbol sizes by address (Thumb symbols have bit 0 set).
    size_at, name_at = {}, {}
    for line in open(f"{work}/{robot}.nm"):
        parts = line.split(maxsplit=3)
        if len(parts) == 4 and parts[2] in "tTwW":
            addr = int(parts[0]) & ~1
            size_at[addr] = max(size_at.get(addr, 0), int(parts[1]))
            name_at.setdefault(addr, parts[3].strip())
    # Call graph: every reference to the start of another function (`bl`, `b.w` tail calls).
    calls, current = defaultdict(set), None
    header = re.compile(r"^([0-9a-f]+) <(.*)>:$")
    target = re.compile(r"\s(?:0x)?([0-9a-f]+) <[^>+]*>")
    for line in open(f"{work}/{robot}.s"):
        m = header.match(line)
        if m:
            current = int(m.group(1), 16) & ~1
        elif current is not None and line.startswith(" "):
            for t in target.findall(line):
                t = int(t, 16) & ~1
                if t in size_at and t != current:
                    calls[current].add(t)
    by_name = {n: a for a, n in name_at.items() if n.startswith("eomgen_")}
    for line in open(f"{work}/{robot}.run"):
        p = line.split()
        if p and p[0] == "MEASURE":
            measured[(p[1], p[2], p[3])] = (int(p[4]), int(p[5]))
    for t in SCALARS:
        for f in FUNCTIONS:
            wrapper = f"eomgen_{robot}_{t}_{f}"
            if wrapper not in by_name or (robot, t, f) not in measured:
                sys.exit(f"measure.sh: no figures for {wrapper}\n"
                         + open(f"{work}/{robot}.run").read())
            seen, todo = set(), [by_name[wrapper]]
            while todo:
                a = todo.pop()
                if a not in seen:
                    seen.add(a)
                    todo.extend(calls[a])
            own[(robot, t, f)] = {(robot, a): size_at[a] for a in seen if not shared(name_at[a])}
            shared_used[t].update({name_at[a]: size_at[a] for a in seen if shared(name_at[a])})

out = [f"Measured by `firmware/measure.sh` on the generated code of commit {revision}.", ""]
for r in robots:
    out.append(f"### {r} ({JOINTS[r]} joints)")
    out.append("")
    out.append("| function | flash f32 | flash f64 | stack f32 | stack f64 "
               "| instructions f32 | instructions f64 |")
    out.append("| --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    for f in FUNCTIONS:
        row = [f"`{f}`"]
        row += [kib(sum(own[(r, t, f)].values())) for t in SCALARS]
        row += [f"{measured[(r, t, f)][0]:,} B" for t in SCALARS]
        row += [f"{measured[(r, t, f)][1]:,}" for t in SCALARS]
        out.append("| " + " | ".join(row) + " |")
    union = {t: {} for t in SCALARS}
    for t in SCALARS:
        for f in FUNCTIONS:
            union[t].update(own[(r, t, f)])
    out.append(f"| all 12 together | {kib(sum(union['f32'].values()))} "
               f"| {kib(sum(union['f64'].values()))} | | | | |")
    out.append("")

out.append("Shared routines (libm's sine and cosine, compiler-builtins' `memcpy` and soft-float "
           "`f64` arithmetic), paid once by a firmware and not counted in the rows above: "
           f"{kib(sum(shared_used['f32'].values()))} for f32, "
           f"{kib(sum(shared_used['f64'].values()))} for f64.")
out.append("")
sizes = {}
for line in open(f"{work}/firmware-size.txt"):
    p = line.split()
    if len(p) >= 2 and p[1].isdigit():
        sizes[p[0]] = int(p[1])
out.append("The control-loop example (`src/main.rs`: `Ur5<f32>` mass_matrix, bias, gravity and "
           "forward_dynamics, plus semihosting and float formatting) has "
           f"{kib(sizes.get('.text', 0))} of `.text` and {kib(sizes.get('.rodata', 0))} of "
           "`.rodata` in all.")
print("\n".join(out))
EOF

cat "$work/table.md"
if $write; then
    python3 - "$work/table.md" README.md <<'EOF'
import sys
table = open(sys.argv[1]).read().strip()
path = sys.argv[2]
text = open(path).read()
begin, end = "<!-- measure.sh: begin -->", "<!-- measure.sh: end -->"
head, rest = text.split(begin, 1)
_, tail = rest.split(end, 1)
open(path, "w").write(f"{head}{begin}\n{table}\n{end}{tail}")
EOF
    echo "measure.sh: README.md updated" >&2
fi
