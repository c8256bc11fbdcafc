"""Reading and writing: parameter and study files (TOML), simulation results (NetCDF)."""

from geardyn.io.netcdf import load_dataset, save_dataset
from geardyn.io.toml import (
    GearPairParams,
    PaperBase,
    RunSettings,
    Study,
    StudyInfo,
    SweepSettings,
    builtin_study,
    builtin_study_names,
    format_error,
    load_params,
    load_study,
    paper_study,
    save_params,
    save_study,
)

__all__ = [
    "GearPairParams",
    "PaperBase",
    "RunSettings",
    "Study",
    "StudyInfo",
    "SweepSettings",
    "builtin_study",
    "builtin_study_names",
    "format_error",
    "load_dataset",
    "load_params",
    "load_study",
    "paper_study",
    "save_dataset",
    "save_params",
    "save_study",
]
