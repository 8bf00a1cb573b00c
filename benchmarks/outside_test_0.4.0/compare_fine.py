# ruff: noqa: E501
"""new vs old vs fine (run_fine.py outputs): per scene, max |x - fine| / max |fine| for new and
old (force, radius, energy_input, energy_dissipated) and max |new - old| / max|old|, and the
rows where the contact state (in contact or not) differs from fine.
usage: python compare_fine.py NEW.npz OLD.npz"""

import sys

import numpy as np

new, old = np.load(sys.argv[1]), np.load(sys.argv[2])
names = sorted({k.split("/")[0] for k in new.files}, key=lambda n: new.files.index(n + "/force"))
F = ("force", "contact_radius", "energy_input", "energy_dissipated")
print(
    f"{'scene':26s} " + " ".join(f"{f[:8]:>8s}:new/old/n-o".rjust(30) for f in F) + "  contact!=fine new/old"
)
for n in names:
    cells = []
    for f in F:
        fine = new[f"{n}/fine_{f}"]
        s = max(np.max(np.abs(fine)), 1e-300)
        a = np.max(np.abs(new[f"{n}/{f}"] - fine)) / s
        b = np.max(np.abs(old[f"{n}/{f}"] - old[f"{n}/fine_{f}"])) / s
        c = np.max(np.abs(new[f"{n}/{f}"] - old[f"{n}/{f}"])) / s
        cells.append(f"{a:9.2e}/{b:9.2e}/{c:9.2e}")
    cn = np.count_nonzero((new[f"{n}/contact_radius"] > 0) != (new[f"{n}/fine_contact_radius"] > 0))
    co = np.count_nonzero((old[f"{n}/contact_radius"] > 0) != (old[f"{n}/fine_contact_radius"] > 0))
    print(f"{n:26s} " + " ".join(cells) + f"  {cn}/{co}")
