"""The Python call's overhead: `Design.tessellate(64, 128)` (library samples + NumPy arrays)
against the same library call timed in Rust inside the extension, both on the solved cup, in
one process, alternating batches. Prints medians and the ratios. Both sides stop the clock before
the result is dropped (the arrays are freed after the timing, as the Rust buffers are).

    python bench/peers/py_overhead.py [examples/cup.toml] [repeats]
"""

import statistics
import sys
import time

import pdeshape

path = sys.argv[1] if len(sys.argv) > 1 else "examples/cup.toml"
repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 200
d = pdeshape.Design.load(path)
d.solve()
d.tessellate(64, 128)
py, rust, flat = [], [], []
for _ in range(repeats // 10):
    for _ in range(10):
        t = time.perf_counter()
        r = d.tessellate(64, 128)
        py.append(time.perf_counter() - t)
        del r
    rust.extend(d._rust_samples_seconds(64, 128, 10))
    flat.extend(d._rust_samples_seconds(64, 128, 10, flat=True))
mp, mr, mf = statistics.median(py), statistics.median(rust), statistics.median(flat)
print(f"{path}: 64 x 128 per patch, {len(d.patches)} patches, {repeats} calls each")
print(f"Rust SolvedDesign::samples  median {mr * 1e3:.3f} ms")
print(f"Rust samples + flat arrays  median {mf * 1e3:.3f} ms")
print(f"Python Design.tessellate    median {mp * 1e3:.3f} ms")
print(f"tessellate / (samples + flat arrays) {mp / mf:.3f}  (Python call + NumPy: {100 * (mp / mf - 1):.1f} %)")
print(f"tessellate / samples {mp / mr:.3f}")
