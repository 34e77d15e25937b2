#!/usr/bin/env python3
"""Mitsuba 3 against illumlab on the same scene, strategy, size and spp, in turn (scripts/peer-mitsuba.sh runs it).

Like for like: the scene's OBJ, MTL and camera are converted to Mitsuba (one shape per material, face normals,
two-sided diffuse BSDFs, one-sided area lights, a box pixel filter, the `independent` sampler), with every
material made diffuse (k_s = 0) in both renderers, since Mitsuba 3 has no Phong BSDF. illumlab renders a copy of
the scene with the same change. `emitter` is Mitsuba's `direct` with emitter_samples=1, bsdf_samples=0; `mis` is
emitter_samples=1, bsdf_samples=1 (both power-heuristic MIS of one light and one BSDF sample).

Timed: illumlab's whole `render` process (load, BVH, render, EXR written) against Mitsuba's warm render (the
second `mi.render` of the scene in one process, its kernels compiled and cached; scene loading not counted), each
ROUNDS times, in turn. Both are warm: Mitsuba's kernels compiled (Dr.Jit keeps them on disk), illumlab's tree and
OBJ geometry in its caches (scene::DiskCache: a mesh of 16 384 triangles or more, an OBJ of 1 MiB or more; here the
knot), each filled by an untimed first run. illumlab's process with its caches off is timed too, in the same
rounds. The mean radiance of both images is printed: the same integral, so they must agree.
"""

import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

os.environ.setdefault("DRJIT_LIBLLVM_PATH", "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1")
import drjit as dr  # noqa: E402
import mitsuba as mi  # noqa: E402

mi.set_variant("llvm_ad_rgb")


def read_camera(toml_path):
    text = open(toml_path, encoding="utf-8").read()
    cam = {}
    for key in ("eye", "target", "up"):
        cam[key] = [float(x) for x in re.search(rf"^{key}\s*=\s*\[([^\]]*)\]", text, re.M).group(1).split(",")]
    cam["fov_y"] = float(re.search(r"^fov_y\s*=\s*([-+0-9.eE]+)", text, re.M).group(1))
    obj = re.search(r'^obj\s*=\s*"([^"]+)"', text, re.M).group(1)
    return cam, os.path.join(os.path.dirname(toml_path), obj)


def read_mtl(path):
    mats, cur = {}, None
    for line in open(path, encoding="utf-8"):
        w = line.split()
        if not w or w[0].startswith("#"):
            continue
        if w[0] == "newmtl":
            cur = mats.setdefault(w[1], {"Kd": [0, 0, 0], "Ks": [0, 0, 0], "Ke": None})
        elif w[0] in ("Kd", "Ks", "Ke") and cur is not None:
            cur[w[0]] = [float(x) for x in w[1:4]]
    return mats


def split_obj(obj_path, out_dir):
    """One OBJ per material (Mitsuba has one BSDF or emitter per shape); returns {material: path}."""
    verts, faces, mtllib, cur = [], {}, None, None
    for line in open(obj_path, encoding="utf-8"):
        w = line.split()
        if not w:
            continue
        if w[0] == "v":
            verts.append(w[1:4])
        elif w[0] == "usemtl":
            cur = w[1]
        elif w[0] == "mtllib":
            mtllib = w[1]
        elif w[0] == "f":
            faces.setdefault(cur, []).append([int(x.split("/")[0]) for x in w[1:]])
    paths = {}
    for mat, fs in faces.items():
        used = sorted({i for f in fs for i in f})
        index = {old: new + 1 for new, old in enumerate(used)}
        path = os.path.join(out_dir, f"{mat}.obj")
        with open(path, "w") as f:
            f.writelines(f"v {' '.join(verts[i - 1])}\n" for i in used)
            f.writelines("f " + " ".join(str(index[i]) for i in face) + "\n" for face in fs)
        paths[mat] = path
    return paths, os.path.join(os.path.dirname(obj_path), mtllib)


def diffuse_copy(toml_path, out_dir):
    """The scene with every Ks set to 0, for illumlab (the OBJ is referenced where it is)."""
    _, obj = read_camera(toml_path)
    mtl_src = re.search(r"^mtllib\s+(\S+)", open(obj, encoding="utf-8").read(), re.M).group(1)
    mtl = open(os.path.join(os.path.dirname(obj), mtl_src), encoding="utf-8").read()
    obj_text = open(obj, encoding="utf-8").read().replace(f"mtllib {mtl_src}", "mtllib diffuse.mtl")
    open(os.path.join(out_dir, "diffuse.mtl"), "w").write(re.sub(r"^Ks .*$", "Ks 0 0 0", mtl, flags=re.M))
    open(os.path.join(out_dir, "scene.obj"), "w").write(obj_text)
    toml = open(toml_path, encoding="utf-8").read()
    toml = re.sub(r'^obj\s*=\s*"[^"]+"', 'obj = "scene.obj"', toml, flags=re.M)
    path = os.path.join(out_dir, "scene.toml")
    open(path, "w").write(toml)
    return path


def mitsuba_scene(toml_path, size, spp, strategy, work):
    cam, obj = read_camera(toml_path)
    shapes, mtl = split_obj(obj, work)
    mats = read_mtl(mtl)
    d = {
        "type": "scene",
        "integrator": {"type": "direct", "emitter_samples": 1, "bsdf_samples": 1 if strategy == "mis" else 0},
        "sensor": {
            "type": "perspective",
            "fov": cam["fov_y"],
            "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(origin=cam["eye"], target=cam["target"], up=cam["up"]),
            "sampler": {"type": "independent", "sample_count": spp},
            "film": {"type": "hdrfilm", "width": size, "height": size, "rfilter": {"type": "box"},
                     "pixel_format": "rgb"},
        },
    }
    for name, path in shapes.items():
        m = mats[name]
        shape = {"type": "obj", "filename": path, "face_normals": True,
                 "bsdf": {"type": "twosided", "bsdf": {"type": "diffuse",
                                                        "reflectance": {"type": "rgb", "value": m["Kd"]}}}}
        if m["Ke"] is not None and max(m["Ke"]) > 0:
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": m["Ke"]}}
            shape["bsdf"] = {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0, 0, 0]}}
        d[name] = shape
    return mi.load_dict(d)


def render_mitsuba(scene, spp, seed):
    """Seconds of one render (evaluated: Dr.Jit is lazy) and the image's mean radiance."""
    start = time.perf_counter()
    arr = np.array(mi.render(scene, spp=spp, seed=seed))
    dr.sync_thread()
    return time.perf_counter() - start, float(arr[..., :3].mean())


def render_illumlab(binary, toml, strategy, size, spp, seed, out, cache):
    """Seconds of the whole `illumlab render` process and the image's mean radiance; `cache` is the folder of
    illumlab's caches, or None to turn them off."""
    cmd = [binary, "render", toml, "--strategy", strategy, "--spp", str(spp), "--size", f"{size}x{size}",
           "--seed", str(seed), "-o", out]
    env = dict(os.environ, XDG_CACHE_HOME=cache or "", ILLUMLAB_CACHE="on" if cache else "off")
    start = time.perf_counter()
    subprocess.run(cmd, check=True, capture_output=True, env=env)
    seconds = time.perf_counter() - start
    return seconds, float(np.array(mi.Bitmap(out))[..., :3].mean())


def main():
    binary, scenes, strategies = sys.argv[1], sys.argv[2].split(","), sys.argv[3].split(",")
    size, spp, rounds = int(sys.argv[4]), int(sys.argv[5]), int(sys.argv[6])
    print(f"{size}x{size}, {spp} spp, medians of {rounds} rounds in turn; Mitsuba {mi.__version__} llvm_ad_rgb, "
          f"Dr.Jit {dr.__version__}")
    print()
    print("| scene | strategy | illumlab whole process, s | Mitsuba warm render, s | illumlab faster by | "
          "each round's ratio, range | caches off: illumlab s, faster by | mean radiance illumlab / Mitsuba |")
    print("|---|---|---:|---:|---:|---:|---:|---|")
    for scene_path in scenes:
        name = os.path.basename(scene_path).removesuffix(".toml")
        with tempfile.TemporaryDirectory() as work:
            toml = diffuse_copy(scene_path, work)
            for strategy in strategies:
                scene = mitsuba_scene(toml, size, spp, strategy, work)
                out, cache = os.path.join(work, "illumlab.exr"), os.path.join(work, "cache")
                render_mitsuba(scene, spp, 0)  # compiles the kernels: what follows is warm
                render_illumlab(binary, toml, strategy, size, spp, 0, out, cache)  # fills the tree cache
                times = {"illumlab": [], "mitsuba": [], "built": []}
                means = {}
                for r in range(rounds):
                    t, means["illumlab"] = render_illumlab(binary, toml, strategy, size, spp, r + 1, out, cache)
                    times["illumlab"].append(t)
                    t, means["mitsuba"] = render_mitsuba(scene, spp, r + 1)
                    times["mitsuba"].append(t)
                    times["built"].append(render_illumlab(binary, toml, strategy, size, spp, r + 1, out, None)[0])
                il, mt, built = (sorted(times[k])[rounds // 2] for k in ("illumlab", "mitsuba", "built"))
                # Each round's two runs follow each other, so their ratio shares the machine's speed of the moment.
                ratios = [m / i for i, m in zip(times["illumlab"], times["mitsuba"])]
                print(f"| {name} | {strategy} | {il:.3f} | {mt:.3f} | {mt / il:.2f}x | "
                      f"{min(ratios):.2f}–{max(ratios):.2f}x | {built:.3f}, {mt / built:.2f}x | "
                      f"{means['illumlab']:.4f} / {means['mitsuba']:.4f} |", flush=True)


if __name__ == "__main__":
    main()
