"""Suggested feature lines against a known homography: ``python -m benchmarks.rectify_suggest``.

Each case photographs a frontal texture with a pinhole camera (square pixels, principal point at the
photo's centre, focal length 0.8-1.5 photo widths) turned 15-60 degrees about two axes, over a
cluttered, unevenly lit background, with a lighting gradient across the surface, blur and noise
(1152x864 photos, about a megapixel). :func:`weft.core.rectify.suggest_lines` and a plain baseline
(probabilistic Hough lines on Canny edges, the two largest orientation clusters, each cluster's
vanishing point by least squares, the same rectification) run on every case.

Success: the residual between the suggested rectification and the truth (estimated frontal frame ->
true frontal frame) is a similarity over the suggested frame: at a 3x3 grid of points its local
right angle is kept within 1 degree and its aspect within 2 %. A refusal counts as no success (it
is the right answer only for the ``refuse`` cases: non-repeating noise, neither lines nor repeats).
The ``without`` textures (gravel, grass, wood grain: one family of lines) are tiled samples, so they
repeat exactly; the cells (a jittered hexagonal lattice) do not repeat exactly.

The cases are split once by name (the SHA-1 of the name, as the fill suite does) into a tuning half
and a check half; constants of the detector are chosen on the tuning half only. Aggregates are
given for the whole suite and per half, with the medians and the worst errors.

Writes ``benchmarks/results/rectify_suggest.json`` (machine, date, per-case rows, aggregates) and
prints a table.
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import platform
import statistics
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
from weft.core.errors import GeometryError
from weft.core.examples import RESOURCES
from weft.core.image import load_image
from weft.core.rectify import detect
from weft.core.rectify.detect.segments import homogeneous, work_grey
from weft.core.rectify.detect.vanishing import refine_point
from weft.core.rectify.homography import apply_homography

from .fill_suite_cases import half
from .fixtures import procedural

PHOTO = (1152, 864)
RESULTS = Path(__file__).resolve().parent / "results" / "rectify_suggest.json"


# -- textures ---------------------------------------------------------------------------------------


def _resource(name: str) -> np.ndarray:
    img = load_image(RESOURCES / name).image
    return img if img.ndim == 3 else np.repeat(img[..., None], 3, axis=2)


def _tile(img: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    w, h = size
    reps = (math.ceil(h / img.shape[0]), math.ceil(w / img.shape[1])) + ((1,) if img.ndim == 3 else ())
    return np.tile(img, reps)[:h, :w].astype(np.float32)


def _rgb(grey: np.ndarray, tint=(1.0, 1.0, 1.0)) -> np.ndarray:
    return np.clip(grey[..., None] * np.array(tint, np.float32), 0, 1).astype(np.float32)


def brick() -> np.ndarray:
    return _tile(_resource("perspective-frontal.png"), (1024, 768))


def checkerboard() -> np.ndarray:
    from skimage import data

    board = data.checkerboard().astype(np.float32) / 255.0
    return _rgb(_tile(cv2.resize(board, (300, 300), interpolation=cv2.INTER_NEAREST), (900, 900)) * 0.7 + 0.15)


def tiles(seed: int = 3) -> np.ndarray:
    rng = np.random.default_rng(seed)
    side, grout, n = 96, 6, 10
    img = np.full((side * n, side * n, 3), 0.82, np.float32)
    for i in range(n):
        for j in range(n):
            tone = rng.uniform(0.35, 0.6)
            img[
                i * side + grout // 2 : (i + 1) * side - grout // 2, j * side + grout // 2 : (j + 1) * side - grout // 2
            ] = np.array([tone, tone * 0.8, tone * 0.6])
    img += rng.normal(0, 0.02, img.shape).astype(np.float32)
    return np.clip(cv2.GaussianBlur(img, (0, 0), 0.8), 0, 1)


def text(seed: int = 4) -> np.ndarray:
    rng = np.random.default_rng(seed)
    img = np.full((900, 1000), 237, np.uint8)
    words = "weft rectifies a photographed surface without drawing lines by hand".split()
    y = 60
    while y < 880:
        line = " ".join(rng.choice(words, 6))
        cv2.putText(img, line, (40, y), cv2.FONT_HERSHEY_SIMPLEX, 1.1, 25, 2, cv2.LINE_AA)
        y += 52
    cv2.rectangle(img, (15, 15), (985, 885), 50, 3)
    return _rgb(img.astype(np.float32) / 255.0, (1.0, 0.98, 0.92))


def weave() -> np.ndarray:
    return _rgb(procedural.weave((900, 900), drift=0.0, thread=12.0, seed=1), (0.85, 0.75, 0.55))


def planks(seed: int = 5) -> np.ndarray:
    rng = np.random.default_rng(seed)
    grain = _resource("wood-grain.png")
    grain = _tile(cv2.resize(grain, (grain.shape[1] * 2, grain.shape[0] * 2)), (1400, 700))
    h, w, plank = 900, 1100, 100
    out = np.zeros((h, w, 3), np.float32)
    for r in range(h // plank):
        x = -int(rng.integers(0, 300))
        while x < w:
            length = int(rng.integers(300, 600))
            gx, gy = int(rng.integers(0, grain.shape[1] - 600)), int(rng.integers(0, grain.shape[0] - plank))
            piece = grain[gy : gy + plank, gx : gx + length] * rng.uniform(0.8, 1.1)
            a, b = max(x, 0), min(x + length, w)
            if b > a:
                out[r * plank : (r + 1) * plank, a:b] = piece[:, a - x : b - x]
                out[r * plank : (r + 1) * plank, a : min(a + 3, w)] *= 0.4
            x += length
        out[r * plank : r * plank + 3] *= 0.4
    return np.clip(out, 0, 1)


def gravel() -> np.ndarray:
    return _tile(_resource("gravel.png"), (900, 900))


def grass() -> np.ndarray:
    return _tile(_resource("grass.png"), (900, 900))


def cells() -> np.ndarray:
    return _rgb(procedural.cells((900, 900), drift=0.0, spacing=40.0, seed=2), (0.7, 0.75, 0.55))


def wood() -> np.ndarray:
    """One family of lines only (the grain); a tiled sample, so it repeats."""
    grain = _resource("wood-grain.png")
    return _tile(cv2.resize(grain, (grain.shape[1] * 2, grain.shape[0] * 2)), (900, 900))


def noise(seed: int = 6) -> np.ndarray:
    """Blotches of filtered noise, not tiled: no lines and no repeats, the suggestion must refuse."""
    rng = np.random.default_rng(seed)
    grey = cv2.GaussianBlur(rng.standard_normal((900, 900)).astype(np.float32), (0, 0), 4.0)
    grey = 0.5 + 0.25 * grey / grey.std()
    return _rgb(np.clip(grey, 0, 1), (0.8, 0.7, 0.6))


STRAIGHT = {
    "brick": brick,
    "checkerboard": checkerboard,
    "tiles": tiles,
    "text": text,
    "weave": weave,
    "planks": planks,
}
WITHOUT = {"gravel": gravel, "grass": grass, "cells": cells, "wood": wood}
REFUSE = {"noise": noise}


# -- the camera and the scene ----------------------------------------------------------------------


def camera(
    frontal_size: tuple[int, int],
    photo_size: tuple[int, int],
    *,
    tilt: float,
    phi: float,
    roll: float,
    focal: float,
    cover: float = 0.55,
    shift=(0.0, 0.0),
) -> np.ndarray:
    """Frontal pixel -> photo homography: the surface (centred on the optical axis, plus ``shift``
    in surface widths) seen by a camera turned ``tilt`` degrees about the axis at ``phi`` degrees
    from the surface's x axis, rolled ``roll`` degrees; focal length ``focal`` photo widths; the
    distance such that the surface would span ``cover`` of the photo's width seen frontally."""
    fw, fh = frontal_size
    pw, ph = photo_size
    f = focal * pw
    t, p, r = (math.radians(v) for v in (tilt, phi, roll))
    axis = np.array([math.cos(p), math.sin(p), 0.0])
    kx = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    rot_tilt = np.eye(3) + math.sin(t) * kx + (1 - math.cos(t)) * kx @ kx
    rz = np.array([[math.cos(r), -math.sin(r), 0], [math.sin(r), math.cos(r), 0], [0, 0, 1]])
    rot = rz @ rot_tilt
    u = 1.0 / fw  # world units per frontal pixel: the surface is 1 wide
    dist = f / (cover * pw)
    centre = np.array([(fw - 1) / 2 + shift[0] * fw, (fh - 1) / 2 + shift[1] * fw])
    k = np.array([[f, 0, (pw - 1) / 2], [0, f, (ph - 1) / 2], [0, 0, 1.0]])
    m = np.column_stack([rot[:, 0] * u, rot[:, 1] * u, np.array([0, 0, dist]) - rot[:, :2] @ (centre * u)])
    h = k @ m
    return h / h[2, 2]


def background(photo_size: tuple[int, int], rng: np.random.Generator) -> np.ndarray:
    """An unevenly lit wall with clutter: shapes and strokes at random angles."""
    pw, ph = photo_size
    yy, xx = np.mgrid[0:ph, 0:pw].astype(np.float32)
    g = 0.35 + 0.35 * (xx / pw) * rng.uniform(0.5, 1) + 0.2 * (yy / ph)
    img = np.repeat(g[..., None], 3, axis=2) * np.array([0.9, 0.92, 1.0], np.float32)
    for _ in range(25):
        colour = tuple(float(v) for v in rng.uniform(0.1, 0.9, 3))
        cx, cy = (int(v) for v in rng.uniform(0, 1, 2) * (pw, ph))
        kind = rng.integers(0, 3)
        if kind == 0:
            cv2.ellipse(
                img,
                (cx, cy),
                (int(rng.integers(10, 80)), int(rng.integers(10, 80))),
                float(rng.uniform(0, 180)),
                0,
                360,
                colour,
                -1,
                cv2.LINE_AA,
            )
        elif kind == 1:
            box = cv2.boxPoints(
                ((cx, cy), (float(rng.uniform(20, 150)), float(rng.uniform(10, 90))), float(rng.uniform(0, 180)))
            )
            cv2.fillPoly(img, [box.astype(np.int32)], colour, cv2.LINE_AA)
        else:
            a = rng.uniform(0, math.pi)
            ln = rng.uniform(40, 250)
            cv2.line(
                img,
                (cx, cy),
                (int(cx + ln * math.cos(a)), int(cy + ln * math.sin(a))),
                colour,
                int(rng.integers(1, 5)),
                cv2.LINE_AA,
            )
    return np.clip(img, 0, 1)


@dataclass(frozen=True)
class Case:
    name: str
    texture: str
    kind: str  # "straight", "without" or "refuse"
    tilt: float
    phi: float
    roll: float
    focal: float
    blur: float
    noise: float
    seed: int


def photograph(case: Case, frontal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The case's photo and its true homography (frontal pixel -> photo)."""
    from .fixtures.synthetic import render_photo

    rng = np.random.default_rng(case.seed)
    fsize = (frontal.shape[1], frontal.shape[0])
    shift = tuple(rng.uniform(-0.08, 0.08, 2))
    h = camera(fsize, PHOTO, tilt=case.tilt, phi=case.phi, roll=case.roll, focal=case.focal, shift=shift)
    # lighting across the surface: a linear ramp in the frontal frame
    yy, xx = np.mgrid[0 : fsize[1], 0 : fsize[0]].astype(np.float32)
    a = rng.uniform(0, 2 * math.pi)
    ramp = 1.0 + 0.35 * ((xx / fsize[0] - 0.5) * math.cos(a) + (yy / fsize[1] - 0.5) * math.sin(a))
    lit = np.clip(frontal * ramp[..., None], 0, 1).astype(np.float32)
    photo = render_photo(lit, h, PHOTO, supersample=2, background=background(PHOTO, rng))
    if case.blur > 0:
        photo = cv2.GaussianBlur(photo, (0, 0), case.blur)
    photo = np.clip(photo + rng.normal(0, case.noise, photo.shape).astype(np.float32), 0, 1)
    return photo.astype(np.float32), h


def cases() -> list[Case]:
    out = []
    tilts = (15.0, 30.0, 45.0, 60.0)
    for i, name in enumerate(STRAIGHT):
        for j, tilt in enumerate(tilts):
            seed = 100 + 10 * i + j
            rng = np.random.default_rng(seed)
            out.append(
                Case(
                    f"{name}-{int(tilt)}",
                    name,
                    "straight",
                    tilt,
                    float(rng.uniform(20, 70)) * rng.choice([-1, 1]),
                    float(rng.uniform(-8, 8)),
                    float(rng.uniform(0.8, 1.5)),
                    (0.0, 0.8, 1.5, 0.8)[j],
                    (0.01, 0.02, 0.015, 0.03)[j],
                    seed,
                )
            )
    for i, name in enumerate({**WITHOUT, **REFUSE}):
        for j, tilt in enumerate((20.0, 35.0, 50.0)):
            seed = 500 + 10 * i + j
            rng = np.random.default_rng(seed)
            kind = "without" if name in WITHOUT else "refuse"
            out.append(
                Case(
                    f"{name}-{int(tilt)}",
                    name,
                    kind,
                    tilt,
                    float(rng.uniform(20, 70)) * rng.choice([-1, 1]),
                    float(rng.uniform(-8, 8)),
                    float(rng.uniform(0.8, 1.5)),
                    0.8,
                    0.015,
                    seed,
                )
            )
    return out


# -- scoring ----------------------------------------------------------------------------------------


def residual(h_est: np.ndarray, h_true: np.ndarray, size: tuple[int, int]) -> tuple[float, float]:
    """Worst deviation from a right angle (degrees) and from aspect 1 (fraction) of the residual
    (estimated frontal -> true frontal) at a 3x3 grid over the estimated frame."""
    r = np.linalg.inv(h_true) @ h_est
    w, h = size
    worst_a = worst_s = 0.0
    eps = 1e-2
    for x in np.linspace(0, w - 1, 3):
        for y in np.linspace(0, h - 1, 3):
            q = apply_homography(r, np.array([[x, y], [x + eps, y], [x, y + eps]]))
            a, b = q[1] - q[0], q[2] - q[0]
            cos = abs(a @ b) / (np.linalg.norm(a) * np.linalg.norm(b))
            worst_a = max(worst_a, abs(90.0 - math.degrees(math.acos(min(1.0, cos)))))
            worst_s = max(worst_s, abs(np.linalg.norm(a) / np.linalg.norm(b) - 1.0))
    return worst_a, worst_s


def hough_baseline(photo: np.ndarray) -> detect.Suggestion:
    """Probabilistic Hough lines on Canny edges; the two largest orientation clusters (peaks of a
    length-weighted angle histogram at least 20 degrees apart); each cluster's vanishing point by
    least squares; the same rectification as the suggestion."""
    grey, k = work_grey(photo)
    edges = cv2.Canny(grey, 60, 150)
    found = cv2.HoughLinesP(edges, 1, np.pi / 360, threshold=40, minLineLength=max(grey.shape) // 25, maxLineGap=4)
    if found is None or len(found) < 10:
        raise GeometryError(detect.REFUSAL)
    seg = (found.reshape(-1, 4).astype(np.float64) + 0.5) / k - 0.5
    d = seg[:, 2:] - seg[:, :2]
    length = np.hypot(d[:, 0], d[:, 1])
    ang = np.degrees(np.arctan2(d[:, 1], d[:, 0])) % 180.0
    hist = np.bincount((ang // 2).astype(int) % 90, weights=length, minlength=90)
    first = int(np.argmax(hist))
    far = [b for b in np.argsort(-hist) if min(abs(b - first), 90 - abs(b - first)) >= 10]
    if not far or hist[far[0]] <= 0:
        raise GeometryError(detect.REFUSAL)
    second = int(far[0])
    h, w = photo.shape[:2]
    c = np.array([(w - 1) / 2.0, (h - 1) / 2.0])
    s = max(w, h) / 2.0
    lines = homogeneous((seg - np.tile(c, 2)) / s)
    members, vps = [], []
    for b in (first, second):
        diff = np.abs(((ang - (b * 2 + 1)) + 90) % 180 - 90)
        mem = np.flatnonzero(diff <= 3.0)
        if len(mem) < 2:
            raise GeometryError(detect.REFUSAL)
        members.append(mem)
        vps.append(refine_point(lines[mem], length[mem]))
    explained = float(length[np.concatenate(members)].sum() / length.sum())
    return detect.suggestion_from_families(
        seg, np.array(vps), members, explained, (w, h), source="hough", min_confidence=0.0
    )


def run_one(fn, photo: np.ndarray, h_true: np.ndarray, repeats: int) -> dict:
    times, cpu = [], []
    out: dict = {}
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            sug = fn(photo)
            err = None
        except GeometryError as e:
            sug, err = None, str(e)
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    out["first_ms"] = round(times[0] * 1000, 1)
    out["median_ms"] = round(statistics.median(times) * 1000, 1)
    out["median_cpu_ms"] = round(statistics.median(cpu) * 1000, 1)
    if sug is None:
        out.update(refused=True, message=err, success=False)
        return out
    ang, asp = residual(sug.homography, h_true, sug.lines.frontal_size)
    out.update(
        refused=False,
        angle_err_deg=round(ang, 3),
        aspect_err=round(asp, 4),
        success=bool(ang <= 1.0 and asp <= 0.02),
        confidence=round(sug.confidence, 3),
        angle_between_deg=round(sug.angle_deg, 1),
        source=sug.source,
        aspect=sug.aspect,
    )
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.rectify_suggest", description=__doc__.split("\n")[0])
    ap.add_argument(
        "--repeats", type=int, default=5, help="timed runs per case and tool (median; the first is kept too)"
    )
    ap.add_argument("--json", type=Path, default=RESULTS)
    ap.add_argument("--only", default=None, help="cases whose names start with this")
    args = ap.parse_args(argv)
    textures: dict[str, np.ndarray] = {}
    rows = []
    makers = {**STRAIGHT, **WITHOUT, **REFUSE}
    for case in cases():
        if args.only and not case.name.startswith(args.only):
            continue
        if case.texture not in textures:
            textures[case.texture] = makers[case.texture]()
        photo, h_true = photograph(case, textures[case.texture])
        row = {
            "case": case.name,
            "half": half(case.name),
            "kind": case.kind,
            "tilt_deg": case.tilt,
            "axis_deg": round(case.phi, 1),
            "focal_widths": round(case.focal, 2),
            "blur": case.blur,
            "noise": case.noise,
            "megapixels": round(photo.shape[0] * photo.shape[1] / 1e6, 3),
        }
        # interleaved: the suggestion and the baseline on the same photo, one after the other
        row["weft"] = run_one(lambda p: detect.suggest_lines(p), photo, h_true, args.repeats)
        row["hough"] = run_one(hough_baseline, photo, h_true, args.repeats)
        if case.kind == "refuse":  # the right answer there is the refusal
            for tool in ("weft", "hough"):
                row[tool]["success"] = row[tool]["refused"]
        rows.append(row)
        w, b = row["weft"], row["hough"]
        print(
            f"{case.name:18} {row['half']:6} {case.kind:8} weft {'ok ' if w['success'] else 'no '}"
            f"{w.get('angle_err_deg', '-')!s:>7} {w.get('aspect_err', '-')!s:>7} {w['median_ms']:6.1f} ms "
            f"{w.get('source', 'refused'):8} | hough {'ok ' if b['success'] else 'no '}"
            f"{b.get('angle_err_deg', '-')!s:>7} {b.get('aspect_err', '-')!s:>7} {b['median_ms']:6.1f} ms",
            flush=True,
        )

    def agg(kind: str, tool: str, part: str = "all") -> dict:
        mine = [x for x in rows if x["kind"] == kind and part in ("all", x["half"])]
        sel = [r[tool] for r in mine]
        if not sel:
            return {}
        ok = [r for r in sel if not r["refused"]]
        return {
            "cases": len(sel),
            "success": round(sum(r["success"] for r in sel) / len(sel), 3),
            "refused": sum(r["refused"] for r in sel),
            "wrong_warps": sum(not r["refused"] and not r["success"] for r in sel),
            "median_angle_err_deg": round(statistics.median(r["angle_err_deg"] for r in ok), 3) if ok else None,
            "median_aspect_err": round(statistics.median(r["aspect_err"] for r in ok), 4) if ok else None,
            "worst_angle_err_deg": round(max(r["angle_err_deg"] for r in ok), 3) if ok else None,
            "worst_aspect_err": round(max(r["aspect_err"] for r in ok), 4) if ok else None,
            "median_ms_per_mp": round(
                statistics.median(r["median_ms"] / x["megapixels"] for r, x in zip(sel, mine, strict=True)), 1
            ),
            "median_cpu_ms_per_mp": round(
                statistics.median(r["median_cpu_ms"] / x["megapixels"] for r, x in zip(sel, mine, strict=True)), 1
            ),
            "worst_ms_per_mp": round(max(r["median_ms"] / x["megapixels"] for r, x in zip(sel, mine, strict=True)), 1),
            "first_run_ms": sel[0]["first_ms"],
        }

    kinds = ("straight", "without", "refuse")
    aggregates = {tool: {kind: agg(kind, tool) for kind in kinds} for tool in ("weft", "hough")}
    by_half = {
        part: {tool: {kind: agg(kind, tool, part) for kind in kinds} for tool in ("weft", "hough")}
        for part in ("tuning", "check")
    }
    data = {
        "suite": "rectify_suggest",
        "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "machine": {
            "platform": platform.platform(),
            "python": platform.python_version(),
            "cpus": os.cpu_count(),
            "processor": platform.processor() or platform.machine(),
            "opencv": cv2.__version__,
            "note": f"load average {os.getloadavg()[0]:.1f} at the end (other jobs on the machine slow the "
            "wall time); median_cpu_ms is the process's CPU time, over the wall time where OpenCV uses two "
            "threads; no numba in the detector, so the first call's time is the first case's first run",
        },
        "command": "python -m benchmarks.rectify_suggest" + (f" --repeats {args.repeats}" if args.repeats != 5 else ""),
        "success_rule": "residual right angle within 1 deg and aspect within 2 % at a 3x3 grid over the frame",
        "aggregates": aggregates,
        "aggregates_by_half": by_half,
        "split": {part: [r["case"] for r in rows if r["half"] == part] for part in ("tuning", "check")},
        "rows": rows,
    }
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(data, indent=1) + "\n")
    print(json.dumps({"all": aggregates, **by_half}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
