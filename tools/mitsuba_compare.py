#!/usr/bin/env python3
"""Check raylab's Monte Carlo references against an independent renderer, Mitsuba 3.

Run by hand, never in CI (it needs Mitsuba and takes minutes):

    python3 -m venv /tmp/mitsuba && /tmp/mitsuba/bin/pip install mitsuba numpy
    /tmp/mitsuba/bin/python tools/mitsuba_compare.py [--spp 1024] [SCENE.toml ...]

For each scene (default: the global-illumination scenes the grader tile-tests) it translates the
raylab scene file into a Mitsuba scene on the same geometry, renders it with Mitsuba's `path`
integrator (`scalar_rgb`), renders the scene with raylab's `render --pfm` at the same spp, and
prints the ratio of the mean linear radiance (Mitsuba / raylab) per channel, the spread of that
ratio over 16 x 16 tiles, and the SSIM of the two sRGB images (`grader compare`). The numbers go
into docs/GRADING.md by hand.

The translation, and where the two renderers differ on purpose:
- `quad` is Mitsuba's `rectangle` turned from z = 0 onto y = 0; `box` is `cube`; `sphere` is
  Mitsuba's exact sphere where raylab has a subdivided icosahedron; `obj` is loaded as it is.
  Placements are `T * Rz * Ry * Rx * S` as in raylab (src/geometry/mesh.rs).
- `diffuse` is `twosided(diffuse)` (raylab shades both sides of a diffuse surface); `emission` is
  an `area` emitter (front side only in both).
- `glass` is Mitsuba's `dielectric`, which reflects by Fresnel's equations (4% head-on, more at
  grazing angles); raylab's perfect refraction never reflects but on total internal reflection.
  Glass scenes therefore differ by a few percent where the glass is seen.
- A point light of flux Phi is Mitsuba's `point` emitter of intensity Phi / (4 pi).
- raylab's `max_depth` counts the surfaces a path hits, glass included; Mitsuba's counts path
  segments and stops emission at its depth, so Mitsuba's is raylab's + 1. `monte_carlo_direct`
  (direct light through glass) is the `path` integrator with depth 2 on scenes without glass.
"""

import argparse
import math
import pathlib
import subprocess
import sys
import tomllib

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
DEFAULT_SCENES = ["cornell_area", "lights_mixed", "cornell_path", "glass_light"]


def placement(mi, obj):
    t = obj.get("translate", [0, 0, 0])
    r = obj.get("rotate", [0, 0, 0])
    s = obj.get("scale", [1, 1, 1])
    T = mi.ScalarTransform4f
    return (
        T().translate(t)
        @ T().rotate([0, 0, 1], r[2])
        @ T().rotate([0, 1, 0], r[1])
        @ T().rotate([1, 0, 0], r[0])
        @ T().scale(s)
    )


def material(desc):
    if desc["kind"] == "diffuse":
        return {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": desc["albedo"]}}}
    if desc["kind"] == "glass":
        return {"type": "dielectric", "int_ior": desc["ior"], "ext_ior": 1.0}
    raise SystemExit(f"material kind {desc['kind']} has no Mitsuba translation")


def mitsuba_scene(mi, path, spp):
    scene = tomllib.loads(path.read_text())
    cam, integ = scene["camera"], scene["integrator"]
    T = mi.ScalarTransform4f
    kind = integ["kind"]
    if kind == "path_tracer":
        depth = integ.get("max_depth", 8) + 1
    elif kind == "monte_carlo_direct":
        if any(m["kind"] == "glass" for m in scene["materials"].values()):
            raise SystemExit(f"{path}: direct lighting through glass has no Mitsuba integrator here")
        depth = 2
    else:
        raise SystemExit(f"{path}: integrator {kind} is not a Monte Carlo one")
    d = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": depth},
        "sensor": {
            "type": "perspective",
            "fov_axis": "y",
            "fov": cam["fov"],
            "to_world": T().look_at(origin=cam["position"], target=cam["look_at"], up=cam["up"]),
            "film": {"type": "hdrfilm", "width": cam["width"], "height": cam["height"], "rfilter": {"type": "box"}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
    }
    for i, obj in enumerate(scene.get("objects", [])):
        m = placement(mi, obj)
        shape = obj["shape"]
        if shape == "quad":
            s = {"type": "rectangle", "to_world": m @ T().rotate([1, 0, 0], -90)}
        elif shape == "box":
            s = {"type": "cube", "to_world": m}
        elif shape == "sphere":
            s = {"type": "sphere", "to_world": m}
        elif shape == "obj":
            s = {"type": "obj", "filename": str(path.parent / obj["file"]), "to_world": m, "face_normals": True}
        else:
            raise SystemExit(f"{path}: shape {shape} has no Mitsuba translation")
        s["bsdf"] = material(scene["materials"][obj["material"]])
        if "emission" in obj:
            s["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": obj["emission"]}}
        d[f"shape{i}"] = s
    for i, light in enumerate(scene.get("lights", [])):
        intensity = [phi / (4 * math.pi) for phi in light["flux"]]
        d[f"light{i}"] = {"type": "point", "position": light["position"], "intensity": {"type": "rgb", "value": intensity}}
    return d


def read_pfm(path):
    data = path.read_bytes()
    header = data.split(b"\n", 3)
    width, height = map(int, header[1].split())
    scale = float(header[2])
    dtype = "<f4" if scale < 0 else ">f4"
    pixels = np.frombuffer(header[3], dtype=dtype, count=width * height * 3).reshape(height, width, 3)
    return pixels[::-1].astype(np.float64)  # PFM rows run bottom-up


def tile_ratios(a, b, tile=16):
    h, w, _ = a.shape
    ratios = []
    for y in range(0, h, tile):
        for x in range(0, w, tile):
            ma, mb = a[y : y + tile, x : x + tile].mean(), b[y : y + tile, x : x + tile].mean()
            if mb > 1e-3:
                ratios.append(ma / mb)
    return np.array(ratios)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scenes", nargs="*", help="scene files (default: the tile-tested scenes)")
    parser.add_argument("--spp", type=int, default=1024)
    parser.add_argument("--out", default=str(ROOT / "target" / "mitsuba"))
    args = parser.parse_args()
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    scenes = [pathlib.Path(s) for s in args.scenes] or [ROOT / "scenes" / f"{n}.toml" for n in DEFAULT_SCENES]
    subprocess.run(["cargo", "build", "--quiet", "--release", "-p", "raylab", "-p", "raylab-grade", "--bin", "render", "--bin", "grader"], cwd=ROOT, check=True)
    rows = []
    for path in scenes:
        name = path.stem
        print(f"{name}: Mitsuba {mi.__version__}, {args.spp} spp", file=sys.stderr)
        image = np.array(mi.render(mi.load_dict(mitsuba_scene(mi, path, args.spp)), spp=args.spp), dtype=np.float64)
        mi.Bitmap(image.astype(np.float32)).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt8, srgb_gamma=True).write(str(out / f"{name}.mitsuba.png"))
        print(f"{name}: raylab, {args.spp} spp", file=sys.stderr)
        pfm, png = out / f"{name}.raylab.pfm", out / f"{name}.raylab.png"
        subprocess.run([ROOT / "target/release/render", path, "-o", png, "--pfm", pfm, "--spp", str(args.spp)], check=True, stderr=subprocess.DEVNULL)
        ours = read_pfm(pfm)
        ratio = image.reshape(-1, 3).mean(0) / ours.reshape(-1, 3).mean(0)
        tiles = tile_ratios(image, ours)
        compared = subprocess.run([ROOT / "target/release/grader", "compare", out / f"{name}.mitsuba.png", png], capture_output=True, text=True, check=True)
        ssim = float(compared.stdout.split("\n")[0].rsplit(" ", 1)[1])
        rows.append((name, ratio, np.percentile(tiles, 5), np.percentile(tiles, 95), ssim))
    print(f"\nMitsuba {mi.__version__} (scalar_rgb, path) against raylab, {args.spp} spp each\n")
    print("| scene | mean ratio Mitsuba / raylab (r, g, b) | 16x16 tiles: 5th-95th percentile ratio | SSIM |")
    print("|---|---|---|---|")
    for name, ratio, lo, hi, ssim in rows:
        print(f"| {name} | {ratio[0]:.4f}, {ratio[1]:.4f}, {ratio[2]:.4f} | {lo:.3f} - {hi:.3f} | {ssim:.4f} |")


if __name__ == "__main__":
    main()
