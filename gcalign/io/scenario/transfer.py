"""The `align.transfer` section: transfer alignment of a slave IMU against a master INS
(``specs/006-transfer-alignment.md``; PSINS demo ``test_align_transfer_fog_mems``).

::

    imu_file: ../tests/data/transfer_align_fog_mems.mat   # the slave (PSINS mat: mimu)
    align:
      mode: transfer
      transfer:
        imu_variable: mimu           # PSINS mat: [dθ(3) dv(3) t], rad, m/s, s
        reference: {path: null, format: psins-mat, variable: fogavp}
                                     # the master; path null: the imu_file itself; a
                                     # relative path: relative to the imu_file's folder;
                                     # 10 columns [att v lat lon h t] or 7 [v lat lon h t]
        matching: attitude+velocity  # | velocity | attitude
        flexure: true                # θ, ω second-order Markov (21 states)
        feedback: {bias: true, attitude: false}
        lever_arm_m: [0, 0, 0]       # slave relative to master, body frame
        gravity: normal              # | constant (g0 = 9.7803267715)
        p0: {attitude_deg: 10, velocity_mps: 10, gyro_bias_dph: 500, accel_bias_ug: 1000,
             mounting_deg: 1, flexure_angle_deg: 0.1, flexure_rate_dps: 10}
        r: {attitude_arcmin: 10, velocity_mps: 0.1}
        q: {arw_dpsh: 0.1, vrw_ugpshz: 10}
        flexure_model: {beta_per_s: [0.5, 0.4, 10], sigma_arcmin: [0.6, -1.0, 0.7]}

The defaults are the demo's. User units in the keys; :meth:`TransferConfig.settings`
converts them once to the SI :class:`gcalign.transfer.TransferSettings`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Literal

from pydantic import Field

from gcalign.io.scenario import bounds as B
from gcalign.io.scenario.base import Model, PosVec3, Vec3, vector
from gcalign.units import ARCMIN, DEG, DPH, DPSH, UG, UGPSHZ


class Reference(Model):
    path: Path | None = Field(None, description="the master's file; null: the imu_file")
    format: Literal["psins-mat"] = "psins-mat"
    variable: str = Field("fogavp", min_length=1)


class Feedback(Model):
    bias: bool = Field(True, description="ε, ∇ into the compensation after every update")
    attitude: bool = Field(False, description="φ into the slave attitude (demo: off)")


class P0(Model):
    attitude_deg: float = Field(10.0, gt=0)
    velocity_mps: float = Field(10.0, gt=0)
    gyro_bias_dph: float = Field(500.0, gt=0)
    accel_bias_ug: float = Field(1000.0, gt=0)
    mounting_deg: float = Field(1.0, gt=0)
    flexure_angle_deg: float = Field(0.1, gt=0)
    flexure_rate_dps: float = Field(10.0, gt=0)

    def sigma(self) -> tuple[float, ...]:
        return ((self.attitude_deg * DEG,) * 3 + (self.velocity_mps,) * 3
                + (self.gyro_bias_dph * DPH,) * 3 + (self.accel_bias_ug * UG,) * 3
                + (self.mounting_deg * DEG,) * 3 + (self.flexure_angle_deg * DEG,) * 3
                + (self.flexure_rate_dps * DEG,) * 3)


class R(Model):
    attitude_arcmin: float = Field(10.0, gt=0)
    velocity_mps: float = Field(0.1, gt=0)


class Q(Model):
    arw_dpsh: float = Field(0.1, ge=0)
    vrw_ugpshz: float = Field(10.0, ge=0)


class FlexureModel(Model):
    beta_per_s: PosVec3 = vector((0.5, 0.4, 10.0))
    sigma_arcmin: Vec3 = vector((0.6, -1.0, 0.7),
                                description="PSINS markov2 σ (its sign is kept; σ² is used)")


class TransferConfig(Model):
    imu_variable: str = Field("mimu", min_length=1)
    reference: Reference = Field(default_factory=Reference)
    matching: Literal["attitude+velocity", "velocity", "attitude"] = "attitude+velocity"
    flexure: bool = True
    feedback: Feedback = Field(default_factory=Feedback)
    lever_arm_m: Annotated[Vec3, B.TRANSFER_LEVER_ARM_M] = vector(
        description="slave relative to master, body frame, m")
    gravity: Literal["normal", "constant"] = "normal"
    p0: P0 = Field(default_factory=P0)
    r: R = Field(default_factory=R)
    q: Q = Field(default_factory=Q)
    flexure_model: FlexureModel = Field(default_factory=FlexureModel)

    def settings(self, earth=None):
        """The SI settings of the core (:class:`gcalign.transfer.TransferSettings`)."""
        from gcalign.transfer import TransferSettings

        extra = {} if earth is None else {"earth": earth}
        fm = self.flexure_model
        return TransferSettings(
            matching=self.matching, flexure=self.flexure, bias_feedback=self.feedback.bias,
            attitude_feedback=self.feedback.attitude,
            lever_arm_b=(self.lever_arm_m[0], self.lever_arm_m[1], self.lever_arm_m[2]),
            p0_sigma=self.p0.sigma() if self.flexure else self.p0.sigma()[:15],
            r_sigma=(self.r.attitude_arcmin * ARCMIN,) * 3 + (self.r.velocity_mps,) * 3,
            arw=self.q.arw_dpsh * DPSH, vrw=self.q.vrw_ugpshz * UGPSHZ,
            flexure_beta=(fm.beta_per_s[0], fm.beta_per_s[1], fm.beta_per_s[2]),
            flexure_sigma=(fm.sigma_arcmin[0] * ARCMIN, fm.sigma_arcmin[1] * ARCMIN,
                           fm.sigma_arcmin[2] * ARCMIN),
            gravity=self.gravity, **extra)

    def unused(self) -> list[str]:
        """Keys that cannot matter, one line each (shown as warnings)."""
        out = []
        fields = self.model_fields_set
        if not self.flexure and "flexure_model" in fields:
            out.append("align.transfer.flexure_model: cannot matter with flexure: false")
        if not self.flexure and self.p0.model_fields_set & {"flexure_angle_deg",
                                                             "flexure_rate_dps"}:
            out.append("align.transfer.p0.flexure_*: cannot matter with flexure: false")
        if self.matching == "velocity" and "attitude_arcmin" in self.r.model_fields_set:
            out.append("align.transfer.r.attitude_arcmin: cannot matter with velocity matching")
        if self.matching == "attitude" and "velocity_mps" in self.r.model_fields_set:
            out.append("align.transfer.r.velocity_mps: cannot matter with attitude matching")
        return out


def resolved_rows(cfg) -> list[tuple[str, str, str]]:
    """The resolved `align` rows of mode transfer (``gcalign validate``): key, value, note."""
    t = cfg.transfer
    p0, r, q = t.p0, t.r, t.q
    return [
        ("align.mode", "transfer", "slave against master (spec 006)"),
        ("align.transfer.reference", f"{t.reference.path or 'imu_file'} "
         f"({t.reference.format}: {t.reference.variable})", f"slave: {t.imu_variable}"),
        ("align.transfer.matching", t.matching, ""),
        ("align.transfer.flexure", str(t.flexure), "21 states" if t.flexure else "15 states"),
        ("align.transfer.feedback", f"bias {t.feedback.bias}, attitude {t.feedback.attitude}",
         ""),
        ("align.transfer.lever_arm_m", str(t.lever_arm_m), "body frame"),
        ("align.transfer.gravity", t.gravity, ""),
        ("align.transfer.p0", f"{p0.attitude_deg}°, {p0.velocity_mps} m/s, "
         f"{p0.gyro_bias_dph} °/h, {p0.accel_bias_ug} µg, μ {p0.mounting_deg}°", ""),
        ("align.transfer.r", f"{r.attitude_arcmin}′, {r.velocity_mps} m/s", ""),
        ("align.transfer.q", f"ARW {q.arw_dpsh} °/√h, VRW {q.vrw_ugpshz} µg/√Hz", ""),
    ]


def unused(cfg) -> list[str]:
    """The keys of `align` that mode transfer makes void, then the section's own."""
    return [f"align.{k}: cannot matter in align.mode 'transfer' (a gyrocompass key)"
            for k in sorted(cfg.model_fields_set - {"mode", "transfer"})] + cfg.transfer.unused()


def check_align_mode(cfg):
    """The rule between `align.mode` and `align.transfer` (AlignConfig's validator calls
    it): mode transfer needs the section, and the section needs mode transfer."""
    if cfg.mode == "transfer" and cfg.transfer is None:
        raise ValueError("transfer: missing; align.mode 'transfer' needs an align.transfer "
                         "section (at least {} for the defaults)")
    if cfg.mode != "transfer" and cfg.transfer is not None:
        raise ValueError(f"transfer: cannot matter in align.mode {cfg.mode!r}; set "
                         "align.mode: transfer (or --mode transfer) or remove the section")
    return cfg
