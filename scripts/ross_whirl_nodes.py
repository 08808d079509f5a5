"""Why eigenfit's whirl label differs from ROSS's on some modes: per-node orbits of those modes.

Run once, outside CI, with ROSS installed (see scripts/ross_reference.py):

    /work/venvs/rotordyn/bin/python scripts/ross_whirl_nodes.py

For the modes of ROSS's rotor_example where ROSS says "Mixed" and the rule over moving nodes
says forward or backward (ross_reference.json: `whirl` vs `whirl_moving_nodes`), it prints each
node's amplitude (relative to the largest) and ROSS's orbit kappa (sign = whirl sense). Output
quoted in docs/rotordynamics.md.
"""
import warnings

import numpy as np
import ross as rs

warnings.filterwarnings("ignore")
r = rs.rotor_example()
for w, want in [(200.0, 4), (500.0, 4), (1000.0, 7), (1000.0, 8)]:
    modal = r.run_modal(speed=w, num_modes=40, sparse=False)
    k = 0
    for i in range(len(modal.wd)):
        if modal.shapes[i].mode_type != "Lateral" or modal.wd[i] <= 0: continue
        k += 1
        if k != want: continue
        ev = modal.evectors[:, i]; nd = r.number_dof
        amp = np.array([np.hypot(abs(ev[nd*n]), abs(ev[nd*n+1])) for n in range(len(r.nodes))])
        kap = [o.kappa for o in modal.shapes[i].orbits]
        print(f"w={w} mode {want} f={modal.wd[i]/2/np.pi:.4f} ROSS {modal.shapes[i].whirl}")
        for n,(a,kk) in enumerate(zip(amp/amp.max(), kap)): print(f"   node {n} amp {a:.2e} kappa {kk:+.3e}")
