"""Compare an alignment result with the simulation's truth, in units of the reported 1-sigma.

    python examples/alignment/compare.py RESULT.json [TRUTH.json]
"""

import json
import sys
from pathlib import Path

import numpy as np

result = json.loads(Path(sys.argv[1]).read_text())
truth_path = Path(sys.argv[2]) if len(sys.argv) > 2 else Path(__file__).with_name("truth.json")
truth = json.loads(truth_path.read_text())
m, sigma, m_true = np.array(result["M"]), np.array(result["uncertainty"]["M"]), np.array(truth["M"])
z = (m - m_true) / sigma
np.set_printoptions(precision=2, suppress=True)
print("M - M_true, in units of the reported 1-sigma:")
print(z)
# with a drifting bias the alignment estimates its mean over the session (bias_mean), not the turn-on value
bias_true = np.array(truth.get("bias_mean") or truth["bias"])
zb = (np.array(result["bias"]) - bias_true) / np.array(result["uncertainty"]["bias"])
print(f"largest |error| = {np.abs(m - m_true).max():.2e} ({np.abs(z).max():.2f} sigma); "
      f"bias error {np.abs(np.array(result['bias']) - bias_true).max():.2e} {result['units']['bias']} "
      f"({np.abs(zb).max():.2f} sigma, against the {'session mean' if truth.get('bias_mean') else 'turn-on'} bias)")
