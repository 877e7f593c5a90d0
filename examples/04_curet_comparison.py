"""Example 4 — models against a measured BRDF (paper §5.3, Tables 3–4) from Python: CUReT
sample 25 (quarry tile).

The comparison is a dict (the document of ``roughscope curet --sample 25 --json``): the two-point
estimate of Table 3, each model's Table-4 error and gain-free error, the fits and the winner.
The CUReT files are not part of the repository: without them the example says so and exits 77
(the test suite's "skipped"), or 1 when ROUGHSCOPE_REQUIRE_SHARED_DATA=1.
"""
import os
import sys

from roughscope import curet

if not curet.available():
    print("CUReT data not found beside the project (../shared/data/curet)")
    sys.exit(1 if os.environ.get("ROUGHSCOPE_REQUIRE_SHARED_DATA") == "1" else 77)

c = curet.compare(25)
print(f"sample {c['sample']} ({c['name']}): E1/E2 = {c['E1_over_E2']:.6f}, "
      f"sigma/T = {c['sigma_over_T_gaussian']:.4f} (Eq. 17), "
      f"{c['sigma_over_T_exponential']:.4f} (Eq. 19)")
for key, m in c["models"].items():
    if m["available"]:
        print(f"  {m['label']:16s} Table 4 error {m['sse']:8.4f}   gain-free {m['sse_gain']:8.4f}")
print("winner:", c["winner"])
if (abs(c["sigma_over_T_gaussian"] - 0.3957) > 5e-5
        or abs(c["sigma_over_T_exponential"] - 0.7982) > 5e-5):
    sys.exit("Table 3 not reproduced")
