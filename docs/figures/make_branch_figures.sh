#!/usr/bin/env bash
# The continuation figures of docs/continuation.md (the paper's Fig. 3 case): the period-1
# branch over the brute-force bifurcation diagram, bifurcations labelled, the Floquet
# multipliers on the unit circle; and the branch's peak mesh deflection.
#   bash docs/figures/make_branch_figures.sh      (from the repository root; a few minutes)
set -euo pipefail
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
geardyn bifurcation paper_fig3 --range 0.1:4:400 --transient 2000 --samples 32 --quiet \
    --out "$tmp/fig3-bif.nc"
geardyn continue paper_fig3 --range 0.1:4 --over "$tmp/fig3-bif.nc" --quiet \
    --out "$tmp/fig3-branch.nc" --plot docs/figures/branch-fig3-consistent.png
geardyn continue paper_fig3 --range 0.1:4 --quantity deflection_max --quiet \
    --plot docs/figures/branch-fig3-deflection.png
