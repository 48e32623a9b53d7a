"""Regenerate the numbers and figures of docs/reproductions/faraway.md (Faraway et al. 2007).

    python docs/reproductions/faraway_figures.py [--subjects 20] [--seed 0]

Builds synthetic human-like reaches to a 30-shelf layout from :func:`visuomotor_gym.handpath.faraway_path`
plus noise whose scales are calibrated to the paper's natural variation (within-subject 6.7 cm,
between-subject 7.6 cm) and cubic-fit error (1.7 cm), then measures on them what the paper measured:
the Bézier fit errors of Table 1, the prediction errors of Table 2, and our realism measures. Writes
``docs/reproductions/faraway_numbers.json`` and ``docs/reproductions/images/faraway_*.png``.

Everything here is synthetic: a number that was calibrated cannot be "reproduced" by it, and a number
that follows from the generator's own model is a consistency check, not evidence. The page says which.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from visuomotor_gym import handpath as H

HERE = Path(__file__).resolve().parent
OUT = HERE / "images"
NUMBERS = HERE / "faraway_numbers.json"

# ---- layout (modelling choice; Faraway et al. 2007, Sec. 2, give only "three towers (in front of the
# subject, to the right-hand side and 45 deg to the right), at five levels ranging from eye to ankle level and
# two depths (near and far)" and a median reach of 56.7 cm). Body coordinates in metres: x to the subject's
# right, y forward, z up, origin between the feet on the floor.
HOME_M = np.array([0.15, 0.25, 1.00])  # home shelf in front of the right hip (our choice)
TOWER_AZIMUTH_DEG = (0.0, 45.0, 90.0)  # front, 45 deg right, right (sourced)
DEPTH_M = (0.30, 0.50)  # horizontal distance of near / far shelves from the subject (chosen so the
# median reach is close to the paper's 56.7 cm)
LEVEL_M = np.linspace(0.10, 1.55, 5)  # ankle to eye height of a ~1.70 m adult, evenly spaced (our choice)
FORWARD, UP = (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)  # so the paper's lateral axis (forward x up) is +x = right

# ---- synthetic reaches
SAMPLE_HZ = 25.0  # Faraway et al. (2007), Sec. 2: motion capture at 25 Hz
DURATION_S = (0.8, 1.4)  # reach durations, uniform (our choice; only sets the number of samples)
SPEED_SHAPE_SD = 0.2  # log-normal spread of alpha and beta per subject and target (our choice; see page)
# calibration targets (Faraway et al. 2007, Sec. 4, Tables 1-2): replicate and between-subject
# variation, cubic fit error
TARGETS = {"within_cm": 6.7, "between_cm": 7.6, "cubic_cm": 1.7}


def layout() -> np.ndarray:
    """The 30 shelf targets, shape (30, 3): tower-major, then depth, then level (ankle to eye)."""
    rows = []
    for az in np.radians(TOWER_AZIMUTH_DEG):
        for r in DEPTH_M:
            for z in LEVEL_M:
                rows.append([r * np.sin(az), r * np.cos(az), z])
    return np.array(rows)


@dataclass
class Draws:
    """Standard-normal and uniform draws, fixed once so every noise scale reuses them (common numbers)."""

    between: np.ndarray  # (S, K, 6): per subject and target, the two interior control-point offsets
    within: np.ndarray  # (S, K, R, 6): per replicate
    wiggle: np.ndarray  # (S, K, R, 4, 3): interior control points of the degree-5 curve
    speed: np.ndarray  # (S, K, 2): log alpha, log beta, per subject and target (replicates share it)
    duration: np.ndarray  # (S, K, R) in [0, 1)


def draw(rng: np.random.Generator, subjects: int, targets: int, replicates: int = 2) -> Draws:
    return Draws(
        between=rng.standard_normal((subjects, targets, 6)),
        within=rng.standard_normal((subjects, targets, replicates, 6)),
        wiggle=rng.standard_normal((subjects, targets, replicates, 4, 3)),
        speed=rng.standard_normal((subjects, targets, 2)),
        duration=rng.uniform(size=(subjects, targets, replicates)),
    )


_U = np.linspace(0.0, 1.0, 201)


def non_cubic(wiggle: np.ndarray) -> np.ndarray:
    """Degree-5 control points (6, 3) of the part of the curve with interior points ``wiggle`` (and zero
    ends) that no cubic with the same ends can follow: the wiggle minus its least-squares cubic."""
    w = np.vstack([np.zeros(3), wiggle, np.zeros(3)])
    cubic = H.fit_bezier(H.bezier(w, _U) + np.outer(_U, [1e-9, 0.0, 0.0]), 3, s=_U)
    return w - H.elevate_degree(H.elevate_degree(cubic))


def reach(
    target: np.ndarray, offsets: np.ndarray, wiggle: np.ndarray, alpha: float, beta: float, n: int
) -> np.ndarray:
    """One synthetic reach: Faraway's curve with ``offsets`` (body frame, per metre of reach) in place of
    the mean, plus the non-cubic part of a degree-5 ``wiggle`` (metres per metre of reach), sampled at
    ``n`` equal time steps with Beta(alpha, beta) arc-length progress."""
    d = float(np.linalg.norm(target - HOME_M))
    ctrl = H.faraway_control_points(HOME_M, target, forward=FORWARD, up=UP, y1=offsets[:3], y2=offsets[3:])
    ctrl5 = H.elevate_degree(H.elevate_degree(ctrl)) + d * non_cubic(wiggle)
    return H.bezier_at_arc_length(ctrl5, H.beta_progress(np.linspace(0.0, 1.0, n), alpha, beta))


def simulate(draws: Draws, sigma: dict[str, float], targets: np.ndarray) -> list[list[list[np.ndarray]]]:
    """Reaches[s][k][r] for noise scales ``sigma``: "between", "within", "wiggle" (per metre of reach) and
    "speed" (log-normal spread of alpha and beta)."""
    mean = np.r_[H.FARAWAY_Y1, H.FARAWAY_Y2]
    out = []
    for s in range(draws.between.shape[0]):
        per_target = []
        for k, target in enumerate(targets):
            reps = []
            for r in range(draws.within.shape[2]):
                offsets = (
                    mean + sigma["between"] * draws.between[s, k] + sigma["within"] * draws.within[s, k, r]
                )
                alpha = H.FARAWAY_ALPHA * np.exp(sigma["speed"] * draws.speed[s, k, 0])
                beta = H.FARAWAY_BETA * np.exp(sigma["speed"] * draws.speed[s, k, 1])
                duration = DURATION_S[0] + (DURATION_S[1] - DURATION_S[0]) * draws.duration[s, k, r]
                n = round(float(duration) * SAMPLE_HZ) + 1
                reps.append(reach(target, offsets, sigma["wiggle"] * draws.wiggle[s, k, r], alpha, beta, n))
            per_target.append(reps)
        out.append(per_target)
    return out


def cm_median(values) -> float:
    return float(np.median(values) * 100.0)


def natural_variation(reaches) -> tuple[float, float]:
    """(within, between) in cm: Faraway et al.'s (2007, Sec. 4) median of maximum distances over relative time
    between replicate pairs, and from each group's (target's) pointwise median trajectory over subjects."""
    within = [H.path_distance(rs[0], rs[1], align="time", reduce="max") for per in reaches for rs in per]
    between = []
    for k in range(len(reaches[0])):
        group = np.stack([H.resample(reaches[s][k][0], 101, "time") for s in range(len(reaches))])
        med = np.median(group, axis=0)
        between += list(np.linalg.norm(group - med, axis=2).max(axis=1))
    return cm_median(within), cm_median(between)


def cubic_fit_cm(reaches, progress=None) -> float:
    """Median maximum cubic fit error (cm), with s_i the data's arc length or ``progress(relative time)``."""
    errs = []
    for z in (rs[0] for per in reaches for rs in per):
        s = None if progress is None else progress(np.linspace(0.0, 1.0, len(z)))
        errs.append(H.fit_error(z, H.fit_bezier(z, 3, s=s), s=s))
    return cm_median(errs)


def calibrate(
    draws: Draws, targets: np.ndarray, rounds: int = 6
) -> tuple[dict[str, float], dict[str, float]]:
    """Scale the three shape-noise levels until the measured medians hit TARGETS (speed spread fixed).

    The measures grow about linearly with their scales, so a few multiplicative fixed-point rounds do."""
    sigma = {"between": 0.04, "within": 0.04, "wiggle": 0.01, "speed": SPEED_SHAPE_SD}
    for _ in range(rounds):
        reaches = simulate(draws, sigma, targets)
        within, between = natural_variation(reaches)
        cubic = cubic_fit_cm(reaches)
        # the between-subject spread holds the within part too: scale the total variance, keep the new
        # within part, give the rest to the between part
        total = (sigma["between"] ** 2 + sigma["within"] ** 2) * (TARGETS["between_cm"] / between) ** 2
        sigma["wiggle"] *= TARGETS["cubic_cm"] / cubic
        sigma["within"] *= TARGETS["within_cm"] / within
        sigma["between"] = float(np.sqrt(max(total - sigma["within"] ** 2, 1e-6)))
    reaches = simulate(draws, sigma, targets)
    within, between = natural_variation(reaches)
    return sigma, {
        "within_cm": within,
        "between_cm": between,
        "cubic_cm": cubic_fit_cm(reaches),
        "median_beta_cm": cubic_fit_cm(reaches, H.beta_progress),
    }


def axis_offsets(p: np.ndarray, frame: np.ndarray) -> np.ndarray:
    """(P1 - A1, P2 - A2) of a cubic in the body frame, shape (2, 3)."""
    axis = p[0] + np.outer([1 / 3, 2 / 3], p[3] - p[0])
    return (p[1:3] - axis) @ frame.T


def evaluate(reaches, targets: np.ndarray) -> dict:
    """Every per-reach error of the two tables on the first replicate of each (subject, target)."""
    frame = H.body_frame(FORWARD, UP)
    firsts = [(rs[0], k) for per in reaches for k, rs in enumerate(per)]
    fits = {deg: [H.fit_bezier(z, deg) for z, _ in firsts] for deg in (1, 2, 3, 4)}
    res = {f"fit_degree_{deg}": [H.fit_error(z, p) for (z, _), p in zip(firsts, fits[deg])] for deg in fits}

    # speed-profile rows: cubic fitted with s_i from a timing model instead of the data's arc length
    for name, prog in (
        ("speed_median_beta", H.beta_progress),
        ("speed_minimum_jerk", H.minimum_jerk_progress),
    ):
        errs = []
        for z, _ in firsts:
            s = prog(np.linspace(0.0, 1.0, len(z)))
            errs.append(H.fit_error(z, H.fit_bezier(z, 3, s=s), s=s))
        res[name] = errs

    # null models from the fitted cubics (Faraway et al. 2007, Sec. 4), refitted on these synthetic data
    cubics = fits[3]
    lengths = np.array([np.linalg.norm(p[3] - p[0]) for p in cubics])
    axis = np.stack([axis_offsets(p, frame) for p in cubics])  # (N, 2, 3), metres, body frame
    endpoint = np.stack([np.vstack([p[1] - p[0], p[2] - p[3]]) @ frame.T for p in cubics])
    means = {
        "axis_distance_scaled": (axis / lengths[:, None, None]).mean(axis=0),
        "axis": axis.mean(axis=0),
        "end_point": endpoint.mean(axis=0),
    }
    res["refit_mean_offsets"] = {k: v.tolist() for k, v in means.items()}
    # the same refit on the noiseless model paths (26 samples, Beta arc-length timing): what the
    # arc-length fit does to the model's own control points, without any noise
    clean = [H.fit_bezier(H.faraway_path(HOME_M, t, 26, forward=FORWARD, up=UP)) for t in targets]
    res["refit_mean_offsets"]["noiseless_axis_distance_scaled"] = np.mean(
        [axis_offsets(p, frame) / np.linalg.norm(p[3] - p[0]) for p in clean], axis=0
    ).tolist()

    def predicted(kind: str, z: np.ndarray) -> np.ndarray:
        p0, p3, n = z[0], z[-1], len(z)
        tau = np.linspace(0.0, 1.0, n)
        d = np.linalg.norm(p3 - p0)
        if kind == "minimum_jerk":
            return H.minimum_jerk_path(p0, p3, n)
        if kind == "faraway":
            return H.faraway_path(p0, p3, n, forward=FORWARD, up=UP)
        if kind == "faraway_parameter":
            return H.faraway_path(p0, p3, n, forward=FORWARD, up=UP, progress="parameter")
        m = means[kind] @ frame  # body -> world
        if kind == "end_point":
            ctrl = np.vstack([p0, p0 + m[0], p3 + m[1], p3])
        else:
            scale = d if kind == "axis_distance_scaled" else 1.0
            ctrl = np.vstack([p0, p0 + np.outer([1 / 3, 2 / 3], p3 - p0) + scale * m, p3])
        return H.bezier_at_arc_length(ctrl, H.beta_progress(tau))

    kinds = ("minimum_jerk", "faraway", "faraway_parameter", "end_point", "axis", "axis_distance_scaled")
    for kind in kinds:
        res[f"predict_{kind}"] = [
            H.path_distance(z, predicted(kind, z), align="time", reduce="max") for z, _ in firsts
        ]
        res[f"spatial_{kind}"] = [H.path_distance(z, predicted(kind, z), reduce="max") for z, _ in firsts]

    # realism measures of the synthetic humans and of straight minimum-jerk reaches between the same ends
    human = [H.hand_path_realism(z, 1.0 / SAMPLE_HZ, forward=FORWARD, up=UP) for z, _ in firsts]
    straight = [
        H.hand_path_realism(H.minimum_jerk_path(z[0], z[-1], len(z)), forward=FORWARD, up=UP)
        for z, _ in firsts
    ]
    res["realism_human"] = [(h.faraway_max_at_median_reach, h.curvature_index, h.faraway_mean) for h in human]
    res["realism_straight"] = [
        (h.faraway_max_at_median_reach, h.curvature_index, h.faraway_mean) for h in straight
    ]
    res["reach_length"] = lengths.tolist()
    res["peak_time"] = [h.peak_time for h in human]
    return res


# ---------------------------------------------------------------------------------------------------
# figures
# ---------------------------------------------------------------------------------------------------
VIEWS = (
    ("top view", 0, 1, "right (cm)", "forward (cm)"),
    ("front view", 0, 2, "right (cm)", "up (cm)"),
    ("side view", 1, 2, "forward (cm)", "up (cm)"),
)


def figure_layout(targets: np.ndarray) -> None:
    """Predicted reaches to the 30 targets (Faraway et al. 2007, Fig. 7 style), straight lines dashed."""
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.4))
    for ax, (title, i, j, xl, yl) in zip(axes, VIEWS):
        for t in targets:
            path = H.faraway_path(HOME_M, t, 60, forward=FORWARD, up=UP) * 100
            ax.plot(path[:, i], path[:, j], color="tab:blue", lw=1.2)
            ax.plot(
                [HOME_M[i] * 100, t[i] * 100], [HOME_M[j] * 100, t[j] * 100], color="0.6", lw=0.7, ls="--"
            )
        ax.plot(targets[:, i] * 100, targets[:, j] * 100, "k.", ms=5)
        ax.plot(HOME_M[i] * 100, HOME_M[j] * 100, "r*", ms=10)
        ax.set(title=title, xlabel=xl, ylabel=yl, aspect="equal")
    fig.suptitle(
        "Faraway's chosen model (axis offsets x reach length, Beta(1.63, 1.75) timing) to the 30 "
        "shelves of our layout; dashed: straight line; star: home shelf"
    )
    fig.tight_layout()
    fig.savefig(OUT / "faraway_layout_paths.png", dpi=110)
    plt.close(fig)


def figure_group(reaches, targets: np.ndarray, k: int) -> None:
    """20 synthetic subjects to one target (Faraway et al. 2007, Fig. 2 style) with the model and the
    straight line."""
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.4))
    t = targets[k]
    model = H.faraway_path(HOME_M, t, 60, forward=FORWARD, up=UP) * 100
    for ax, (title, i, j, xl, yl) in zip(axes, VIEWS):
        for s in range(len(reaches)):
            z = reaches[s][k][0] * 100
            ax.plot(z[:, i], z[:, j], color="0.55", lw=0.8, marker=".", ms=2)
        ax.plot(model[:, i], model[:, j], color="tab:blue", lw=2.2, label="faraway_path")
        ax.plot(
            [HOME_M[i] * 100, t[i] * 100],
            [HOME_M[j] * 100, t[j] * 100],
            color="tab:red",
            lw=1.5,
            ls="--",
            label="straight (Flash-Hogan)",
        )
        ax.set(title=title, xlabel=xl, ylabel=yl, aspect="equal")
    axes[0].legend(loc="best", fontsize=8)
    fig.suptitle(
        f"Synthetic reaches of 20 subjects to target {k} (tower 45 deg right, far, ankle level), "
        "25 Hz samples in grey"
    )
    fig.tight_layout()
    fig.savefig(OUT / "faraway_synthetic_group.png", dpi=110)
    plt.close(fig)


def figure_fit(z: np.ndarray) -> None:
    """One synthetic reach with its linear and cubic fits and the cubic's control points (Fig. 4 style)."""
    p1, p3 = H.fit_bezier(z, 1), H.fit_bezier(z, 3)
    u = np.linspace(0.0, 1.0, 100)
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.4))
    for ax, (title, i, j, xl, yl) in zip(axes, VIEWS):
        ax.plot(z[:, i] * 100, z[:, j] * 100, "k.", ms=5, label="samples (25 Hz)")
        c = H.bezier(p3, u) * 100
        ax.plot(
            c[:, i], c[:, j], color="tab:blue", lw=1.8, label=f"cubic fit ({H.fit_error(z, p3) * 100:.1f} cm)"
        )
        ax.plot(p3[:, i] * 100, p3[:, j] * 100, "o--", color="tab:blue", ms=5, lw=0.6, mfc="none")
        ax.plot(
            p1[:, i] * 100,
            p1[:, j] * 100,
            color="tab:red",
            lw=1.2,
            label=f"linear ({H.fit_error(z, p1) * 100:.1f} cm)",
        )
        ax.set(title=title, xlabel=xl, ylabel=yl, aspect="equal")
    axes[0].legend(loc="best", fontsize=8)
    fig.suptitle(
        "Arc-length least-squares fit (Faraway et al. 2007, Sec. 3.2) of one synthetic reach; circles: "
        "cubic control points; legend: maximum error"
    )
    fig.tight_layout()
    fig.savefig(OUT / "faraway_fit_example.png", dpi=110)
    plt.close(fig)


def figure_speed(targets: np.ndarray) -> None:
    """Relative speed profiles: Faraway's Beta, minimum jerk (= Beta(3, 3)), and the two timings of the
    model's curve for a right-front reach."""
    tau = np.linspace(0.0, 1.0, 401)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.0))
    ax = axes[0]
    for (a, b), lab, col in (
        ((1.63, 1.75), "Beta(1.63, 1.75), Faraway", "tab:blue"),
        ((3.0, 3.0), "Beta(3, 3) = minimum jerk", "tab:red"),
        ((2.0, 2.0), "Beta(2, 2) (the paper's slip)", "0.6"),
    ):
        ax.plot(tau, np.gradient(H.beta_progress(tau, a, b), tau), color=col, label=lab)
    ax.axvline(H.beta_peak_time(), color="tab:blue", ls=":", lw=1)
    ax.axvline(0.48, color="k", ls=":", lw=1)
    ax.text(0.49, 1.85, "0.48 (paper)", fontsize=8)
    ax.text(0.24, 1.85, "0.457 (mode)", fontsize=8, color="tab:blue")
    ax.set(
        xlabel="relative time",
        ylabel="relative speed (path lengths per duration)",
        title="Relative speed profiles",
    )
    ax.legend(fontsize=8, loc="lower center")
    ax = axes[1]
    for k, col in ((12, "tab:green"), (2, "tab:purple"), (27, "tab:orange")):
        t = targets[k]
        for prog, ls in (("arc_length", "-"), ("parameter", "--")):
            path = H.faraway_path(HOME_M, t, 401, forward=FORWARD, up=UP, progress=prog)
            v = np.linalg.norm(np.gradient(path, tau, axis=0), axis=1) / np.linalg.norm(t - HOME_M)
            ax.plot(tau, v, color=col, ls=ls, label=f"target {k}, {prog}")
    ax.set(
        xlabel="relative time",
        ylabel="speed / reach length (per duration)",
        title="faraway_path timing: arc_length (solid), parameter (dashed)",
    )
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(OUT / "faraway_speed_profiles.png", dpi=110)
    plt.close(fig)


def figure_errors(res: dict) -> None:
    """Per-reach maximum errors over relative time, and the realism measures."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.0))
    ax = axes[0]
    bins = np.linspace(0, 30, 61)
    for key, lab, col in (
        ("predict_minimum_jerk", "Flash-Hogan (straight, min. jerk)", "tab:red"),
        ("predict_faraway", "Faraway's model", "tab:blue"),
        ("fit_degree_3", "cubic fit", "tab:green"),
    ):
        v = np.array(res[key]) * 100
        ax.hist(v, bins=bins, histtype="step", lw=1.5, color=col, label=f"{lab}: median {np.median(v):.1f}")
    ax.set(
        xlabel="maximum error over the reach (cm)", ylabel="reaches", title="Per-reach errors, synthetic data"
    )
    ax.legend(fontsize=8)
    ax = axes[1]
    h, s = np.array(res["realism_human"]), np.array(res["realism_straight"])
    ax.scatter(h[:, 1], h[:, 0] * 100, s=6, color="0.4", label="synthetic humans")
    ax.scatter(s[:, 1], s[:, 0] * 100, s=6, color="tab:red", label="straight min-jerk reaches")
    ax.set(
        xlabel="curvature_index (0 straight, 1 Faraway)",
        ylabel="faraway_max at 56.7 cm reach (cm)",
        title="hand_path_realism on the same 600 reaches",
    )
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(OUT / "faraway_errors_realism.png", dpi=110)
    plt.close(fig)


def quantiles(v, scale: float = 1.0) -> list[float]:
    return [round(float(x) * scale, 2) for x in np.quantile(np.asarray(v), [0.1, 0.25, 0.5, 0.75, 0.9])]


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--subjects", type=int, default=20)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    OUT.mkdir(parents=True, exist_ok=True)
    targets = layout()
    lengths = np.linalg.norm(targets - HOME_M, axis=1)

    draws = draw(np.random.default_rng(args.seed), args.subjects, len(targets))
    sigma, calibrated = calibrate(draws, targets)
    reaches = simulate(draws, sigma, targets)
    res = evaluate(reaches, targets)

    table = {
        k: cm_median(v) for k, v in res.items() if k.startswith(("fit_", "speed_", "predict_", "spatial_"))
    }
    h, s = np.array(res["realism_human"]), np.array(res["realism_straight"])
    numbers = {
        "layout": {
            "home_m": HOME_M.tolist(),
            "depth_m": DEPTH_M,
            "level_m": LEVEL_M.round(4).tolist(),
            "reach_median_cm": round(float(np.median(lengths)) * 100, 1),
            "reach_range_cm": [round(float(lengths.min()) * 100, 1), round(float(lengths.max()) * 100, 1)],
        },
        "noise_per_m_of_reach": {k: round(v, 4) for k, v in sigma.items()},
        "calibrated_cm": {k: round(v, 2) for k, v in calibrated.items()},
        "median_max_error_cm": {k: round(v, 2) for k, v in table.items()},
        "refit_mean_offsets_body": {k: np.round(v, 4).tolist() for k, v in res["refit_mean_offsets"].items()},
        "realism_quantiles_10_25_50_75_90": {
            "human_faraway_max_at_567_cm": quantiles(h[:, 0], 100),
            "straight_faraway_max_at_567_cm": quantiles(s[:, 0], 100),
            "human_curvature_index": quantiles(h[:, 1]),
            "straight_curvature_index": quantiles(s[:, 1]),
            "human_peak_time": quantiles(res["peak_time"]),
        },
        "settings": {
            "subjects": args.subjects,
            "seed": args.seed,
            "replicates": 2,
            "sample_hz": SAMPLE_HZ,
            "duration_s": DURATION_S,
            "speed_shape_log_sd": SPEED_SHAPE_SD,
        },
    }
    NUMBERS.write_text(json.dumps(numbers, indent=1) + "\n")
    print(json.dumps(numbers, indent=1))

    figure_layout(targets)
    figure_group(reaches, targets, k=15)
    figure_fit(reaches[0][27][0])
    figure_speed(targets)
    figure_errors(res)


if __name__ == "__main__":
    main()
