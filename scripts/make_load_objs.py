#!/usr/bin/env python3
"""Writes the OBJ files of BENCHMARKS.md's loading figures (issue 28) into a folder.

    python3 scripts/make_load_objs.py /tmp/load

gN.obj: N triangles, each in a `g` group of its own; uN.obj: N triangles, each
switching material (`usemtl`, two materials of m.mtl in turn), for N = 50,000 and
200,000; big.obj: 7,000,000 `v` lines (231 MB) and one face, for `--max-memory`.
"""

import sys
from pathlib import Path


def triangles(path: Path, count: int, statement: str) -> None:
    with path.open("w") as f:
        if statement == "usemtl":
            f.write("mtllib m.mtl\n")
        for i in range(count):
            b = i * 3
            x, y = i % 1000, i // 1000
            f.write(f"v {x} {y} 0\nv {x + 0.5} {y} 0\nv {x} {y + 0.5} 0\n")
            f.write(f"g group{i}\n" if statement == "g" else f"usemtl m{i % 2}\n")
            f.write(f"f {b + 1} {b + 2} {b + 3}\n")


def vertices(path: Path) -> None:
    chunk = "".join(
        f"v {i * 0.001:.6f} {i * 0.002:.6f} {i * 0.003:.6f}\n" for i in range(100_000)
    )
    with path.open("w") as f:
        for _ in range(70):
            f.write(chunk)
        f.write("f 1 2 3\n")


def main() -> None:
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "load")
    out.mkdir(parents=True, exist_ok=True)
    (out / "m.mtl").write_text("newmtl m0\nKd 1 0 0\nnewmtl m1\nKd 0 1 0\n")
    for count in (50_000, 200_000):
        triangles(out / f"g{count}.obj", count, "g")
        triangles(out / f"u{count}.obj", count, "usemtl")
    vertices(out / "big.obj")


if __name__ == "__main__":
    main()
