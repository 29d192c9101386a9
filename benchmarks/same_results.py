"""Are two trees of results files the same to the bit? (A speed change must keep them.)

Every dataset of every ``*.h5`` in DIR_A is compared with the file of the same name in
DIR_B by ``np.array_equal`` (NaN equal to NaN); wall and compute times are listed apart.
Make the trees with the two checkouts, e.g. for each seed-000 config and a §5.3 batch::

    for c in configs/seed000_*.yaml; do
        PYTHONPATH=A python -m gcalign align $c -o a/$(basename $c .yaml).h5; done
    PYTHONPATH=A python -m gcalign batch gcalign/scenarios/seed000_moving_full_cycle.yaml \
        --seeds 20 -w 1 -o a/mc_batch.h5

Run: ``python benchmarks/same_results.py DIR_A DIR_B [--rtol R]`` (exit 1 if any dataset
differs). ``--rtol R``: a float dataset that is not identical but within R of the larger of
the two arrays' largest magnitude counts as "within R" (for a change allowed to move
results by round-off, such as the Kalman kernels against their NumPy form, 1e-12), and
its largest relative difference is printed.
"""

from __future__ import annotations

import sys
from pathlib import Path

import h5py
import numpy as np

TIMES = ("wall_s", "compute_s")  #: datasets that measure the machine, not the run


def datasets(f: h5py.File) -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {}
    f.visititems(lambda n, o: out.__setitem__(n, o[()]) if isinstance(o, h5py.Dataset)
                 else None)
    return out


def main() -> int:
    args = sys.argv[1:]
    rtol = None
    if "--rtol" in args:
        i = args.index("--rtol")
        rtol = float(args[i + 1])
        del args[i:i + 2]
    a_dir, b_dir = (Path(p) for p in args[:2])
    compared = differ = within = 0
    for fa in sorted(a_dir.glob("*.h5")):
        with h5py.File(fa) as A, h5py.File(b_dir / fa.name) as B:
            da, db = datasets(A), datasets(B)
            for name in sorted(set(da) ^ set(db)):
                print(f"only in one file: {fa.name}:{name}")
                differ += 1
            for name in sorted(set(da) & set(db)):
                x, y = da[name], db[name]
                compared += 1
                same = (np.array_equal(x, y, equal_nan=True) if x.dtype.kind in "fc"
                        else np.array_equal(x, y))
                if not same and rtol is not None and x.dtype.kind == "f" and x.shape == y.shape:
                    scale = max(float(np.nanmax(np.abs(x), initial=0.0)),
                                float(np.nanmax(np.abs(y), initial=0.0)), 1e-300)
                    rel = float(np.nanmax(np.abs(x - y), initial=0.0)) / scale
                    if rel <= rtol and np.array_equal(np.isnan(x), np.isnan(y)):
                        within += 1
                        print(f"within {rtol:g} (largest {rel:.1e}): {fa.name}:{name}")
                        continue
                if not same:
                    timing = name.rsplit("/", 1)[-1] in TIMES
                    print(f"{'timing, differs' if timing else 'DIFFERS'}: {fa.name}:{name}")
                    differ += 0 if timing else 1
    print(f"{compared} datasets compared, {differ} differ"
          + ("" if rtol is None else f", {within} within {rtol:g}"))
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
