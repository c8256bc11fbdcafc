"""Execution: lane tasks run in chunks, here or on a Dask cluster (:mod:`.executor`), resumable
through a Zarr store (:mod:`.zarr_store`). Above the numerics (:mod:`geardyn.solvers`), below the
analyses that plan the runs (see ``tests/test_layers.py``)."""
