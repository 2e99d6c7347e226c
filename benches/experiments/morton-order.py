#!/usr/bin/env python3
"""Rewrite a scene of `raystep generate spheres` with its [[sphere]] entries in the
order of a 32-bit Morton code of their centres' (x, z), for timing only (the object
ids change, so its pictures' `object` buffer differs from the original's).

    python3 benches/experiments/morton-order.py IN.toml OUT.toml
"""
import re
import sys


def main(source, target):
    text = open(source).read()
    first = text.index("[[sphere]]")
    head, entries = text[:first], text[first:].split("[[sphere]]")[1:]
    entries = ["[[sphere]]" + e if e.endswith("\n") else "[[sphere]]" + e + "\n" for e in entries]
    centre = re.compile(r"center = \[([^,]+), ([^,]+), ([^\]]+)\]")
    points = []
    for e in entries:
        m = centre.search(e)
        points.append((float(m.group(1)), float(m.group(3))))
    (x0, x1), (z0, z1) = [(min(v), max(v)) for v in zip(*points)]

    def code(p):
        a = int((p[0] - x0) / (x1 - x0 + 1e-9) * 65535)
        b = int((p[1] - z0) / (z1 - z0 + 1e-9) * 65535)
        return sum(((a >> k) & 1) << (2 * k) | ((b >> k) & 1) << (2 * k + 1) for k in range(16))

    order = sorted(range(len(entries)), key=lambda k: code(points[k]))
    with open(target, "w") as out:
        out.write(head + "".join(entries[k] for k in order))


if __name__ == "__main__":
    main(*sys.argv[1:3])
