"""Scenario files: YAML -> validated pydantic models -> SI values for the core.

The YAML schema is the public contract (docs: Reference, Scenario keys): units in key names,
``extra="forbid"`` so that a misspelt key is an error. Conversion to SI happens here once.
"""

from gcalign.io.scenario.loader import load_scenario, parse_scenario
from gcalign.io.scenario.messages import scenario_errors
from gcalign.io.scenario.models import Scenario

__all__ = ["Scenario", "load_scenario", "parse_scenario", "scenario_errors"]
