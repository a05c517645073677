"""Test-only reference for `accelcal allan`: allantools' overlapping Allan deviation, lag-1
noise identification and Greenhall EDF on a log, printed as JSON. Run by tests/allan_reference.rs.

    python3 tests/allan_reference.py LOG.csv COLUMN RATE_HZ
"""
import json
import sys

import allantools
import allantools.ci as ci
import numpy as np

path, column, rate = sys.argv[1], sys.argv[2], float(sys.argv[3])
with open(path) as f:
    header = f.readline().strip().split(",")
data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
y = data[:, header.index(column)]
taus, devs, errs, ns = allantools.oadev(y, rate=rate, data_type="freq", taus="octave")
alphas = []
for tau in taus:
    m = int(round(tau * rate))
    if len(y) // m >= 30:
        alphas.append(int(ci.autocorr_noise_id(y, m, data_type="freq", dmin=0, dmax=2)[0]))
    else:
        alphas.append(None)
edf = []
for alpha in (-2, -1, 0, 1, 2):
    for m in (1, 2, 8, 64, 1024):
        n_phase = len(y) + 1
        try:
            value = ci.edf_greenhall(alpha=alpha, d=2, m=m, N=n_phase, overlapping=True,
                                     modified=False)
        except NotImplementedError:
            value = None
        edf.append({"alpha": alpha, "m": m, "n_phase": n_phase, "edf": value})
print(json.dumps({"tau_s": list(taus), "adev": list(devs), "alpha": alphas, "edf": edf,
                  "allantools": allantools.__version__}))
