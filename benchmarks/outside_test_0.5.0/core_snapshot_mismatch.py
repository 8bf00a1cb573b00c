"""Snapshot of one contact restored into a simulator of another (other material / numerics).
docs/architecture.md: "a Snapshot may be restored into another simulator of the same contact".
Is a mismatch refused, or does the other simulator silently continue with foreign memory?"""

import sys

import numpy as np

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from _scene import contact  # noqa: E402

from viscoadh_ros.core.simulator import ContactSimulator  # noqa: E402

a = ContactSimulator(contact())
a.step_depths(np.linspace(1e-3, 0.1, 100), np.linspace(1e-6, 50e-6, 100))
snap = a.snapshot()
ref = a.step(0.2, depth=40e-6)
for label, c in (
    ("fast preset", contact(numerics={"preset": "fast"})),
    (
        "K=2 material",
        contact(
            material={
                "glass_shear_modulus": 1e6,
                "kelvin_shear_moduli": [5e4, 1e5],
                "kelvin_viscosities": [1.05e5, 1e5],
            }
        ),
    ),
    ("elastic (closed form)", contact(material={"glass_shear_modulus": 1e6})),
    ("w = 0.5", contact(adhesion={"work_of_adhesion": 0.5})),
):
    b = ContactSimulator(c)
    try:
        b.restore(snap)
        o = b.step(0.2, depth=40e-6)
        print(
            f"{label:22s}: restore accepted; next step force {o.force:.6g} N (own contact gives {ref.force:.6g} N)"
        )
    except Exception as e:  # noqa: BLE001
        print(f"{label:22s}: refused: {type(e).__name__}: {str(e)[:120]}")
