"""The IMU data and truth of a scenario: simulated from `motion`, or read from `imu_file`."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gcalign.errors import ScenarioError
from gcalign.io.results import HDF5_SUFFIXES
from gcalign.io.scenario import Scenario
from gcalign.sim.imu import ImuData, apply_errors, ideal_imu
from gcalign.sim.motions import Truth


@dataclass(frozen=True)
class RunData:
    """What every pipeline starts from: IMU increments, truth if known, site, seed."""

    imu: ImuData
    truth: Truth | None
    site: np.ndarray
    seed: int | None


def read_data_file(path: Path) -> tuple[ImuData, Truth | None]:
    """IMU (and truth, if the file has it) from our HDF5, a PSINS .imu or a CSV/text file."""
    from gcalign.io import results
    from gcalign.io.imu_files import read_imu_file

    path = Path(path)
    if not path.is_file():
        raise ScenarioError(f"imu_file: {path}: file not found")
    if path.suffix.lower() in HDF5_SUFFIXES:
        return results.read_imu(path), results.read_truth(path)
    try:
        return read_imu_file(path), None
    except ValueError as err:
        raise ScenarioError(f"imu_file: {err}") from None


def scenario_data(scenario: Scenario, seed: int | None = None,
                  cache_key: str | None = None) -> RunData:
    """Simulate the scenario's motion with its IMU errors, or read its recorded IMU file.

    `seed` overrides ``imu.seed``; the same scenario and seed give the same numbers.
    `cache_key` (a batch variant) lets successive seeds share the noise-free simulation:
    it is computed once per key in this process (see :func:`cached_noise_free`).
    """
    if cache_key is not None and scenario.imu_file is None:
        return with_errors(scenario, cached_noise_free(scenario, cache_key), seed)
    if scenario.imu_file is not None:
        imu, truth = read_data_file(scenario.imu_file)
        if scenario.site is not None:
            site = scenario.site.to_si()
        elif imu.site is not None:
            site = np.asarray(imu.site, float)
        else:
            raise ScenarioError(
                f"site: missing; {scenario.imu_file} does not give the site, so the scenario must"
            )
        return RunData(imu=imu, truth=truth, site=site, seed=None)
    return with_errors(scenario, noise_free(scenario), seed)


def noise_free(scenario: Scenario) -> RunData:
    """Truth and ideal increments of a simulated scenario: the part that no seed changes
    (a batch computes it once per variant)."""
    if scenario.motion is None:
        raise ScenarioError("motion: missing; the scenario needs 'motion' or 'imu_file'")
    assert scenario.site is not None  # the model requires a site with a motion
    site = scenario.site.to_si()
    truth, ideal = ideal_imu(scenario.motion.to_motion(), site, scenario.imu.ts)
    return RunData(imu=ideal, truth=truth, site=site, seed=None)


def with_errors(scenario: Scenario, ideal: RunData, seed: int | None = None) -> RunData:
    """The scenario's sensor errors applied to noise-free data; `seed` overrides imu.seed."""
    seed = scenario.imu.seed if seed is None else seed
    imu = apply_errors(ideal.imu, scenario.imu.errors(), np.random.default_rng(seed))
    return RunData(imu=imu, truth=ideal.truth, site=ideal.site.copy(), seed=seed)


_NOISE_FREE: dict[str, RunData] = {}  # cache key -> noise-free data, in this process


def cached_noise_free(scenario: Scenario, key: str) -> RunData:
    """:func:`noise_free` computed once per key (a batch variant: truth and ideal increments
    are about 2/3 of a seed 000 run; only the sensor errors depend on the seed). Same
    numbers, bit for bit (tested). The cached arrays are read-only, so code that would
    modify them fails loudly. At most four variants are kept.
    """
    hit = _NOISE_FREE.get(key)
    if hit is None:
        if len(_NOISE_FREE) >= 4:
            _NOISE_FREE.pop(next(iter(_NOISE_FREE)))
        hit = _NOISE_FREE[key] = noise_free(scenario)
        for obj in (hit.truth, hit.imu):
            for value in vars(obj).values():
                if isinstance(value, np.ndarray):
                    value.flags.writeable = False
    return hit
