"""step_depths != step per call: the phase of an edge at rest flickers INDENTING/DETACHING in
step_depths when the batch ends with the row dropped (out of contact, memory relaxed: K = 0
always) -- `_step_depths` takes `rest = self._model.edge_resolution` from the row AFTER the
batch, 0.0 once the row is None, so the at-rest rule (0.3.0 fix) is off for the whole batch.
Same on c28c75b (pre-existing, not this round). Also: energy_dissipated of step_depths
called in chunks differs from step per call in the last bits (cumsum added to the carried
sum: a different association), the docs say "same outputs".

usage: .venv/bin/python repro/step_depths_phase_rest.py   (exit 1 while the bug is there)
"""

import numpy as np
from scenes import CHAINS, SPHERE, contact_of, section

from viscoadh_ros.core.simulator import ContactSimulator

c = contact_of(section(SPHERE, *CHAINS[0]))  # elastic sphere, time_stepped forced
t = np.arange(1, 13) * 1e-3
d = np.array([4e-5, 8e-5, 8e-5, 8e-5, 8e-5, 8e-5, 8e-5, 8e-5, -1e-4, -1e-4, -1e-4, -1e-4])

sim = ContactSimulator(c)
call = [int(sim.step(float(a), depth=float(b)).phase) for a, b in zip(t, d, strict=False)]
batch = [int(p) for p in ContactSimulator(c).step_depths(t, d)["phase"]]
batch_in_contact = [int(p) for p in ContactSimulator(c).step_depths(t[:8], d[:8])["phase"]]
print("step per call     ", call)
print("step_depths (all) ", batch)
print("step_depths (8)   ", batch_in_contact, "(batch ends in contact: agrees)")
raise SystemExit(0 if call == batch else 1)
