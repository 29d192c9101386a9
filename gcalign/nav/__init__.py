"""The shared navigation core: earth models, rotations, the strapdown update and its kernels.

Every capability navigates through this package: :mod:`~gcalign.nav.earth` (earth models
as values), :mod:`~gcalign.nav.rotation` (Euler angles, DCMs, quaternions, rotation vectors)
and :mod:`~gcalign.nav.strapdown` (the public navigation functions over blocks of IMU
increments, forward or in reverse). The numba kernels behind them are private
(:mod:`~gcalign.nav._kernels`). Nothing here imports the CLI, pydantic, yaml, rich or h5py.
"""
