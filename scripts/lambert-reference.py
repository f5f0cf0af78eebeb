#!/usr/bin/env python3
# An independent estimate of block means, for scenes of lambert surfaces lit by emitting
# surfaces (such as the Cornell box), to tell which of two renderers that disagree is right.
#
# Why it exists: our renders and Tungsten's reference of the Cornell box differ by about 1 % on
# the ceiling beside the light, beyond both renderers' noise, and two
# renderers cannot say which of them is off. This one shares no code with either: a brute-force
# CPU path tracer (every ray against every triangle, numpy), next-event estimation only (a point
# on an emitter chosen by area; emission met by a bounce is not counted, so there is no MIS to
# get wrong), cosine-weighted bounces, Russian roulette after three bounces. A path that meets an
# emitter ends there (Tungsten's null bsdf, as on the Cornell box's light); emitters shine from
# the side their normal points to. Pixel samples are jittered by the scene's filter (box or tent)
# as in both renderers, so blocks beside an edge compare too.
#
# It reads the scene as `retile import SCENE --save OUT.retile` writes it, so the geometry is
# Retile's import of the file (the images' edges show whether that matches the other renderer).
# It refuses what it does not model: other materials, textures, lights that are not surfaces, a
# sky, media. It is slow (every triangle per ray): meant for a few blocks of a small scene.
#
# usage: python3 scripts/lambert-reference.py SCENE.retile --size WxH --blocks X,Y,W,H[;X,Y,W,H...]
#            [--samples N] [--seed S] [--image FILE.exr ...]
#   --samples  camera paths per block (default 400000; about 1 minute per 400000 on one core)
#   --image    also print each image's mean over the same blocks (read with oiiotool), with the
#              difference from this estimate in its standard errors
# needs: python3-numpy; oiiotool (openimageio-tools) for --image
import argparse
import base64
import json
import subprocess
import sys

import numpy as np

LUMA = np.array([0.2126, 0.7152, 0.0722])


def fail(msg):
    print("error: " + msg, file=sys.stderr)
    sys.exit(2)


def load_scene(path):
    try:
        with open(path) as f:
            d = json.load(f)
    except (OSError, ValueError) as e:
        fail(f"{path}: {e}")
    if d.get("format") != "retile-scene":
        fail(f"{path}: not a .retile scene (write one with `retile import SCENE --save OUT.retile`)")
    env = d["environment"]
    if env["type"] != "constant" or max(env["color"]) * env["intensity"] > 0:
        fail(f"{path}: the environment shines; only emitting surfaces are modelled")
    if max(env["medium_absorption"] + env["medium_scattering"]) > 0:
        fail(f"{path}: the world holds a medium; media are not modelled")
    if any(l.get("visible", True) for l in d.get("lights", [])):
        fail(f"{path}: the scene has lights that are not surfaces; only emitting surfaces are modelled")
    mats = {m["id"]: m for m in d["materials"]}
    for m in mats.values():
        textured = any(m.get(k, 0) for k in ("albedo_texture", "alpha_texture", "bump_texture", "emission_texture"))
        if m["type"] not in ("lambert", "null") or textured or m.get("blend_with", 0) or m.get("alpha", 1) != 1:
            fail(f"{path}: material '{m['name']}' is not a plain lambert or null surface")
    meshes = {m["id"]: m for m in d["meshes"]}
    v0, e1, e2, albedo, emission, normal = [], [], [], [], [], []
    for o in d["objects"]:
        if not o.get("visible", True):
            continue
        mesh, mat = meshes[o["mesh"]], mats[o["material"]]
        pos = np.frombuffer(base64.b64decode(mesh["positions"]), dtype=np.float32).reshape(-1, 3).astype(np.float64)
        idx = np.frombuffer(base64.b64decode(mesh["indices"]), dtype=np.uint32).reshape(-1, 3)
        xf = np.array(o["transform"], dtype=np.float64).reshape(4, 4)  # row-major, column vectors
        world = pos @ xf[:3, :3].T + xf[:3, 3]
        # The winding's normal, flipped with a mirroring transform, says which side emits.
        flip = -1.0 if np.linalg.det(xf[:3, :3]) < 0 else 1.0
        for a, b, c in idx:
            ea, eb = world[b] - world[a], world[c] - world[a]
            n = np.cross(ea, eb) * flip
            if np.linalg.norm(n) == 0:
                continue
            v0.append(world[a]); e1.append(ea); e2.append(eb); normal.append(n / np.linalg.norm(n))
            # A native file leaves out a colour at its default (material_fields.h).
            albedo.append(mat.get("albedo", [0.8, 0.8, 0.8]) if mat["type"] == "lambert" else [0, 0, 0])
            emission.append(mat.get("emission", [0, 0, 0]))
    geo = {k: np.array(v) for k, v in
           dict(v0=v0, e1=e1, e2=e2, albedo=albedo, emission=emission, normal=normal).items()}
    geo["emitters"] = np.where(geo["emission"].max(1) > 0)[0]
    if len(geo["emitters"]) == 0:
        fail(f"{path}: nothing emits")
    area = 0.5 * np.linalg.norm(np.cross(geo["e1"][geo["emitters"]], geo["e2"][geo["emitters"]]), axis=1)
    geo["emitter_cdf"] = np.cumsum(area) / area.sum()
    geo["emitter_area"] = area.sum()
    return d, geo


def intersect(geo, o, dr, tmax=None):
    """Nearest hit of each ray with every triangle (Moller-Trumbore): distance and index, -1 for none."""
    p = np.cross(dr[:, None, :], geo["e2"][None])
    det = np.einsum("ntk,tk->nt", p, geo["e1"])
    ok = np.abs(det) > 1e-14
    inv = 1.0 / np.where(ok, det, 1.0)
    s = o[:, None, :] - geo["v0"][None]
    u = np.einsum("ntk,ntk->nt", s, p) * inv
    q = np.cross(s, geo["e1"][None])
    v = np.einsum("nk,ntk->nt", dr, q) * inv
    t = np.einsum("ntk,tk->nt", q, geo["e2"]) * inv
    ok &= (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 1e-6)
    if tmax is not None:
        ok &= t < tmax[:, None]
    t = np.where(ok, t, np.inf)
    hit = np.argmin(t, axis=1)
    dist = t[np.arange(len(o)), hit]
    return dist, np.where(np.isfinite(dist), hit, -1)


def radiance(geo, o, dr, rng, max_bounces):
    n = len(o)
    beta, total = np.ones((n, 3)), np.zeros((n, 3))
    alive = np.arange(n)
    for depth in range(max_bounces + 1):
        if len(alive) == 0:
            break
        dist, tri = intersect(geo, o[alive], dr[alive])
        keep = tri >= 0
        alive, dist, tri = alive[keep], dist[keep], tri[keep]
        p = o[alive] + dist[:, None] * dr[alive]
        ng = geo["normal"][tri]
        facing = np.einsum("nk,nk->n", ng, dr[alive]) < 0
        if depth == 0:  # seen by the camera; later emission comes only by the light samples
            total[alive] += geo["emission"][tri] * facing[:, None]
        keep = geo["emission"][tri].max(1) == 0  # an emitter ends the path (a null surface)
        alive, p, tri, ng, facing = alive[keep], p[keep], tri[keep], ng[keep], facing[keep]
        if depth == max_bounces or len(alive) == 0:
            break
        ns = np.where(facing[:, None], ng, -ng)  # lambert is two-sided
        alb = geo["albedo"][tri]
        origin = p + 1e-6 * ns
        # Next-event estimation: a point on the emitters, uniform by area.
        k = geo["emitters"][np.searchsorted(geo["emitter_cdf"], rng.random(len(alive)))]
        su, r2 = np.sqrt(rng.random(len(alive))), rng.random(len(alive))
        q = geo["v0"][k] + (su * (1 - r2))[:, None] * geo["e1"][k] + (su * r2)[:, None] * geo["e2"][k]
        to = q - p
        d = np.linalg.norm(to, axis=1)
        to /= d[:, None]
        cos_s = np.einsum("nk,nk->n", ns, to)
        cos_l = -np.einsum("nk,nk->n", geo["normal"][k], to)
        lit = np.where((cos_s > 0) & (cos_l > 0))[0]
        if len(lit):
            _, block = intersect(geo, origin[lit], to[lit], d[lit] * (1 - 1e-5))
            lit = lit[block < 0]
            g = cos_s[lit] * cos_l[lit] / d[lit] ** 2 * geo["emitter_area"]
            total[alive[lit]] += beta[alive[lit]] * alb[lit] / np.pi * geo["emission"][k[lit]] * g[:, None]
        # The bounce: cosine-weighted, so the weight is the albedo.
        beta[alive] *= alb
        r1, phi = rng.random(len(alive)), 2 * np.pi * rng.random(len(alive))
        a = np.where(np.abs(ns[:, 0:1]) > 0.9, np.array([[0.0, 1, 0]]), np.array([[1.0, 0, 0]]))
        t = np.cross(a, ns)
        t /= np.linalg.norm(t, axis=1, keepdims=True)
        b = np.cross(ns, t)
        r = np.sqrt(r1)
        o[alive] = origin
        dr[alive] = (r * np.cos(phi))[:, None] * t + (r * np.sin(phi))[:, None] * b + np.sqrt(1 - r1)[:, None] * ns
        if depth >= 3:
            survive = np.minimum(beta[alive].max(1), 0.95)
            lives = rng.random(len(alive)) < survive
            beta[alive[lives]] /= survive[lives, None]
            alive = alive[lives]
    return total


def camera_rays(d, size, px, py):
    cam = d["camera"]
    if cam.get("aperture", 0) > 0:
        fail("the camera has an aperture; only a pinhole is modelled")
    eye, target, up = (np.array(cam[k], dtype=np.float64) for k in ("position", "target", "up"))
    fwd = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(fwd, up)
    right /= np.linalg.norm(right)
    upv = np.cross(right, fwd)
    w, h = size
    th = np.tan(cam["vertical_fov"] / 2)
    x = (2 * px / w - 1) * th * w / h
    y = (1 - 2 * py / h) * th
    dr = fwd[None] + x[:, None] * right[None] + y[:, None] * upv[None]
    dr /= np.linalg.norm(dr, axis=1, keepdims=True)
    return np.repeat(eye[None], len(px), 0), dr


def filter_offsets(d, n, rng):
    s = d["settings"]
    kind, width = s.get("pixel_filter", "box"), s.get("filter_width", 1)
    if kind == "box":
        return (rng.random((n, 2)) - 0.5) * width
    if kind == "tent":  # a triangle of radius width / 2: the sum of two uniforms
        return (rng.random((n, 2)) + rng.random((n, 2)) - 1) * width / 2
    fail(f"the pixel filter '{kind}' is not modelled (box and tent are)")


def image_block_means(image, blocks):
    means = []
    for (x, y, w, h) in blocks:
        out = subprocess.run(["oiiotool", image, "--cut", f"{w}x{h}+{x}+{y}", "--printstats"],
                             capture_output=True, text=True)
        line = [l for l in out.stdout.splitlines() if "Stats Avg" in l]
        if out.returncode != 0 or not line:
            fail(f"oiiotool could not read {image}: {out.stderr.strip()}")
        means.append(np.array([float(v) for v in line[0].split(":")[1].split()[:3]]))
    return means


def main():
    ap = argparse.ArgumentParser(description="Block means of a lambert scene by an independent CPU path tracer")
    ap.add_argument("scene")
    ap.add_argument("--size", required=True)
    ap.add_argument("--blocks", required=True)
    ap.add_argument("--samples", type=int, default=400000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--image", action="append", default=[])
    args = ap.parse_args()
    try:
        size = tuple(int(v) for v in args.size.split("x"))
        blocks = [tuple(int(v) for v in b.split(",")) for b in args.blocks.split(";") if b]
        assert len(size) == 2 and all(len(b) == 4 for b in blocks) and args.samples > 0
    except (ValueError, AssertionError):
        fail("--size is WxH, --blocks X,Y,W,H[;X,Y,W,H...], --samples a positive count")
    d, geo = load_scene(args.scene)
    rng = np.random.default_rng(args.seed)
    images = {img: image_block_means(img, blocks) for img in args.image}
    batch = 20000
    for i, (bx, by, bw, bh) in enumerate(blocks):
        sums, sq, count = np.zeros(4), np.zeros(4), 0
        while count < args.samples:
            n = min(batch, args.samples - count)
            pixel = np.stack([bx + rng.integers(0, bw, n), by + rng.integers(0, bh, n)], 1) + 0.5
            film = pixel + filter_offsets(d, n, rng)
            o, dr = camera_rays(d, size, film[:, 0], film[:, 1])
            L = radiance(geo, o, dr, rng, d["settings"]["max_bounces"])
            v = np.concatenate([L, (L @ LUMA)[:, None]], 1)
            sums += v.sum(0)
            sq += (v * v).sum(0)
            count += n
        mean = sums / count
        se = np.sqrt(np.maximum(sq / count - mean ** 2, 0) / count)
        print(f"block {bx},{by},{bw},{bh}: R {mean[0]:.5f} G {mean[1]:.5f} B {mean[2]:.5f} "
              f"luminance {mean[3]:.5f} +- {se[3]:.5f} ({100 * se[3] / mean[3]:.2f} %)", flush=True)
        for img, means in images.items():
            lum = means[i] @ LUMA
            print(f"  {img}: luminance {lum:.5f}, {100 * (lum / mean[3] - 1):+.2f} %, "
                  f"{(lum - mean[3]) / se[3]:+.1f} standard errors of this estimate", flush=True)


if __name__ == "__main__":
    main()
