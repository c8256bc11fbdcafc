"""Reading and writing: parameter and study files (TOML), simulation results (NetCDF)."""

from geardyn.io import toml as _toml
from geardyn.io.netcdf import load_dataset, save_dataset
from geardyn.io.toml import *  # noqa: F403  (the names of toml.__all__)

__all__ = ["load_dataset", "save_dataset", *_toml.__all__]
