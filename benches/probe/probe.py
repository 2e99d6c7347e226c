#!/usr/bin/env python3
"""Probe: which functions that chapters 1-9 include does a render execute?

Runs the release binary under callgrind (line-level, inlined code keeps its own
file:line), then maps executed lines to the bodies of functions defined inside
the ANCHOR regions that the tutorial chapters include."""
import re, subprocess, sys, os, collections, tempfile
ROOT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", ".."))
BIN = os.path.join(ROOT, "target/release/raystep")
chap = [f for f in sorted(os.listdir(f"{ROOT}/chapters")) if re.match(r"0[1-9]-", f)]
inc = set()
for f in chap:
    for m in re.finditer(r"\{\{#(?:rustdoc_)?include \.\./(src/[^:}]+):([a-z_0-9]+)\}\}", open(f"{ROOT}/chapters/{f}").read()):
        inc.add((m.group(1), m.group(2), f))
funcs = {}  # (file, fn) -> (start, end, chapters)
for path, anchor, f in sorted(inc):
    lines = open(f"{ROOT}/{path}").read().split("\n")
    a = b = None
    for i, l in enumerate(lines, 1):
        if re.search(rf"ANCHOR: {anchor}\s*$", l): a = i
        if re.search(rf"ANCHOR_END: {anchor}\s*$", l): b = i
    if a is None or b is None:
        print("anchor not found", path, anchor); continue
    i = a
    while i < b:
        m = re.search(r"\bfn ([a-z_0-9]+)", lines[i - 1])
        if m and not lines[i - 1].strip().startswith("//"):
            # body: from the line with '{' to the matching '}'
            depth, j, started = 0, i, False
            while j <= len(lines):
                for ch in lines[j - 1]:
                    if ch == "{": depth += 1; started = True
                    elif ch == "}": depth -= 1
                if started and depth == 0: break
                j += 1
            key = (path, m.group(1))
            s, e, cs = funcs.get(key, (i, j, set()))
            cs.add(f); funcs[key] = (i, j, cs)
            i = j
        i += 1
def run(args):
    # The callgrind file and the render's pictures go to a folder of their own,
    # removed when the run has been read.
    with tempfile.TemporaryDirectory(prefix="raystep-probe.") as d:
        out = os.path.join(d, "callgrind.out")
        pictures = os.path.join(d, "out")
        subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", "--compress-strings=no",
                        "--compress-pos=no", "--dump-instr=yes", BIN, "render"] + args + ["--width", "64", "--height", "36", "-q",
                        "--out", pictures], check=True, capture_output=True)
        with open(out) as f:
            profile = f.read().split("\n")
    addrs = set(); ob = None; skip = False
    for l in profile:
        if l.startswith("ob="):
            ob = l[3:].strip(); continue
        if l.startswith("calls="):
            skip = True; continue
        m = re.match(r"^0x([0-9a-f]+) \d+ (\d+)", l)
        if m:
            if skip: skip = False; continue
            if ob and ob.endswith("/raystep") and int(m.group(2)) > 0:
                addrs.add(m.group(1))
    res = subprocess.run(["addr2line", "-i", "-a", "-e", BIN], input="\n".join(sorted(addrs)),
                         capture_output=True, text=True).stdout
    hit = collections.defaultdict(set)
    for l in res.split("\n"):
        m = re.match(r"^(/\S+):(\d+)", l)
        if m and m.group(1).startswith(ROOT + "/src/"):
            hit[m.group(1)[len(ROOT) + 1:]].add(int(m.group(2)))
    return hit
runs = {"default": run([]), "--tutorial": run(["--tutorial"]),
        "true-plane": run([f"{ROOT}/scenes/true-plane.toml"])}
total = len(funcs); ran = 0
for (path, fn), (s, e, cs) in sorted(funcs.items()):
    by = [k for k, h in runs.items() if any(s < n <= e for n in h.get(path, ()))]
    ran += bool(by)
    print(f"{'yes' if by else 'NO ':3} {path}:{s}-{e} {fn:28} {','.join(sorted(c[:2] for c in cs)):12} {' '.join(by)}")
print(f"executed {ran} of {total} functions that chapters 1-9 include")
