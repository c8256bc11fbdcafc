#!/usr/bin/env bash
# The continuation figures of docs/continuation.md (the paper's Fig. 3 case, consistent
# interpretation): the period-1 branch over the brute-force bifurcation diagram with its
# bifurcations labelled and the Floquet multipliers on the unit circle; a zoom on the folds
# near Omega = 0.5; the branch's peak mesh deflection.
#   bash docs/figures/make_branch_figures.sh   (from the repository root; ~10 min on 2 cores)
set -euo pipefail
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
geardyn bifurcation paper_fig3 --range 0.1:4:400 --transient 2000 --samples 32 --quiet \
    --out "$tmp/fig3-bif.nc"
geardyn continue paper_fig3 --range 0.1:4 --over "$tmp/fig3-bif.nc" --quiet \
    --out "$tmp/fig3-branch.nc" --plot docs/figures/branch-fig3-consistent.png
geardyn bifurcation paper_fig3 --range 0.38:0.72:171 --transient 2000 --samples 32 --quiet \
    --out "$tmp/fig3-bif-zoom.nc"
geardyn continue paper_fig3 --range 0.38:0.72 --over "$tmp/fig3-bif-zoom.nc" --quiet \
    --plot docs/figures/branch-fig3-folds.png
python - "$tmp/fig3-branch.nc" <<'PY'
import sys

from geardyn.io.netcdf import load_dataset
from geardyn.plotting.branch import plot_branch

plot_branch(load_dataset(sys.argv[1]), "docs/figures/branch-fig3-deflection.png",
            quantity="deflection_max", multipliers=False)
PY
