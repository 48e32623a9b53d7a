"""A brain that knows its own crowding zone: which of this step's samples may be pooled with a neighbour.

With ``VisionParams.crowding`` the retina reports a target whose line of sight lies within the critical
spacing ``crowding_bouma * theta`` of another object's (Bouma 1970) as the average of the group
(compulsory averaging, Parkes et al. 2001; ``visuomotor_gym.vision.periphery.crowding_groups``): a
biased sample whose bias the vision model's covariance does not describe. The walker baselines drop such
samples or fuse them with the spread of the crowding zone instead of as if unbiased (:func:`crowd_std`;
modelling choice: a crowded target is localised only to within its zone, and the samples taken near
the fovea, where crowding does not act, carry the position).
The test uses the *perceived* directions (the agent does not know the true ones); pooling pulls the
group together, so a crowded target still has its neighbour within the spacing.
"""

from __future__ import annotations

import math

from visuomotor_gym.vision.foveation import DEG


def crowded(directions, objects, vision) -> set[int]:
    """Indices of the samples that may be crowded: ``directions`` the perceived eye-frame vectors (x along
    the line of sight, any length > 0) of this step's samples, ``objects`` the object of each (points of
    one object do not crowd one another). Empty without ``vision.crowding`` or foveation."""
    if not (getattr(vision, "crowding", False) and vision.foveated):
        return set()
    units = []
    for x, y, z in directions:
        n = math.sqrt(x * x + y * y + z * z) or 1.0
        units.append((x / n, y / n, z / n))
    fovea = vision.crowding_fovea_deg * DEG
    out = set()
    for i, u in enumerate(units):
        theta = math.acos(max(-1.0, min(1.0, u[0])))
        if theta <= fovea:
            continue
        spacing = vision.crowding_bouma * theta
        for j, v in enumerate(units):
            if objects[j] == objects[i]:
                continue
            cx = u[1] * v[2] - u[2] * v[1]
            cy = u[2] * v[0] - u[0] * v[2]
            cz = u[0] * v[1] - u[1] * v[0]
            if math.atan2(math.sqrt(cx * cx + cy * cy + cz * cz), u[0] * v[0] + u[1] * v[1] + u[2] * v[2]) < spacing:
                out.add(i)
                break
    return out


def crowd_std(distance: float, eccentricity: float, vision) -> float:
    """The std (m) given to a crowded sample at ``distance`` m and ``eccentricity`` rad: half the critical
    spacing, ``0.5 * crowding_bouma * theta * distance`` (modelling choice: a pooled position lies within
    the zone of radius ``b theta`` around the target)."""
    return 0.5 * vision.crowding_bouma * eccentricity * distance
