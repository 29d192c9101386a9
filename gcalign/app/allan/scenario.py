"""The scenario ``gcalign allan --scenario FILE`` writes: the data's site, a static base for
the data's duration (at the attitude of the recording's header, if it has one), and the
fitted noise as its ``imu`` section, so that ``gcalign simulate`` (or any command) runs it
as it is and ``gcalign allan`` of that simulation finds the same terms again."""

from __future__ import annotations

import re


def scenario_mapping(summary: dict) -> dict:
    """The scenario (a mapping) from an `allan` summary."""
    lat, lon, h = summary["site_deg_m"]
    name = re.sub(r"[^A-Za-z0-9_.+-]", "_", f"{summary['scenario']}-noise")
    return {
        "name": name,
        "site": {"lat_deg": float(lat), "lon_deg": float(lon), "height_m": float(h)},
        "motion": {"kind": "static",
                   "attitude_deg": [float(a) for a in summary.get("header_attitude_deg")
                                    or (0.0, 0.0, 0.0)],
                   "duration_s": float(summary["duration_s"])},
        "imu": {**summary["imu"], "seed": 1},
        "output": {"rate_hz": "full"},  # every increment: what `allan` of it reads
        "allan": {"per_decade": summary["per_decade"],
                  "min_clusters": summary["min_clusters"],
                  **({"fit_tau_s": summary["fit_tau_s"]} if summary.get("fit_tau_s") else {})},
    }


def scenario_text(summary: dict) -> str:
    """YAML text of :func:`scenario_mapping`, with a header saying where it came from."""
    import yaml

    head = (f"# IMU noise identified by gcalign allan from {summary['source']}\n"
            f"# ({summary['samples']} samples, {summary['duration_s']:g} s from "
            f"{summary['start_s']:g} s); terms not resolved are left out (0)\n")
    return head + yaml.safe_dump(scenario_mapping(summary), sort_keys=False)
