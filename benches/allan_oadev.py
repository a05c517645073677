"""allantools' oadev on the samples `cargo bench --bench allan` wrote (raw little-endian f64),
in memory, at octave tau: the median of repeated runs, with the minimum and maximum.

    python3 benches/allan_oadev.py [DIR] [REPEATS]    (defaults target/allan-bench, 5)
"""
import statistics
import sys
import time

import allantools
import numpy as np

directory = sys.argv[1] if len(sys.argv) > 1 else "target/allan-bench"
repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 5
y = np.fromfile(f"{directory}/samples.f64", dtype="<f8")
times, cpu = [], []
for _ in range(repeats):
    start, c0 = time.perf_counter(), time.process_time()
    taus, devs, errs, ns = allantools.oadev(y, rate=100.0, data_type="freq", taus="octave")
    times.append(time.perf_counter() - start)
    cpu.append(time.process_time() - c0)
print(f"{len(y)} samples, {len(taus)} octave taus, allantools {allantools.__version__}, "
      f"numpy {np.__version__}")
print(f"allantools.oadev in memory: median {statistics.median(times):.3f} s "
      f"(min {min(times):.3f}, max {max(times):.3f}); CPU median {statistics.median(cpu):.2f} s")
