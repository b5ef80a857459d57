"""Renders a scene on a Ray cluster: one Ray task per sample range, the films merged as they
arrive, the image written as OpenEXR. A command line over ``volpt.distributed.render``.

    pip install './python[ray]'                  # volpt and Ray, on every node

    # a local cluster on this machine, two worker processes:
    python python/examples/ray_render.py scenes/example/cube.xml --spp 64 --parts 4 \\
        --local-cpus 2 -o cube.exr

    # a real cluster (`ray start --head` on one node, `ray start --address HEAD:6379` on the
    # others; the scene at the same path on every node, e.g. a shared file system):
    python ray_render.py /shared/scenes/cgg-logo/scene.xml --spp 4096 --parts 32 \\
        --address auto --backend cuda -o cgg-logo.exr --parts-dir /shared/parts

Each part is a task reserving one GPU (``--backend cuda``) or ``--num-cpus`` CPUs; a task whose
worker or node dies is run again (``--max-retries``). The image equals the one-process render
of the same samples within float64 rounding of the sums, and the same ``--parts`` give the same
bits every time. See docs/distributed.md.
"""

import argparse
import sys
import time

import volpt
import volpt.distributed


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scene", help="the scene file, at this path on every node")
    p.add_argument("-o", "--output", required=True, help="the image to write (.exr or .png)")
    p.add_argument("--spp", type=int, required=True, help="samples per pixel of the whole render")
    p.add_argument("--parts", type=int, help="tasks (sample ranges); default: the cluster's GPUs or CPUs")
    p.add_argument("--seed", type=int, help="the render's seed (default: the scene's)")
    p.add_argument("--backend", choices=["auto", "cpu", "cuda"], default="auto",
                   help="auto: cuda where the cluster has GPUs, else cpu")
    p.add_argument("--resolution", help="WxH, overriding the scene's film")
    p.add_argument("-D", dest="params", action="append", default=[], metavar="NAME=VALUE",
                   help="a scene parameter, as volpt render -D")
    p.add_argument("--num-cpus", type=int, default=1, help="CPUs (and threads) per CPU task")
    p.add_argument("--max-retries", type=int, default=3, help="runs again of a task whose worker died")
    p.add_argument("--parts-dir", help="also write each part's film here (part-0003.vfilm), for volpt merge")
    cluster = p.add_mutually_exclusive_group()
    cluster.add_argument("--address", help="the Ray cluster (auto, HOST:PORT, ray://...); default: "
                         "RAY_ADDRESS, a cluster started on this machine, else a new local one")
    cluster.add_argument("--local-cpus", type=int, help="start a local cluster of this many CPUs")
    args = p.parse_args(argv)

    settings = {}
    if args.resolution:
        w, _, h = args.resolution.partition("x")
        settings["resolution"] = (int(w), int(h))
    params = dict(kv.split("=", 1) for kv in args.params)

    import ray  # volpt.distributed says what to install where it is missing

    if args.local_cpus is not None:
        ray.init(address="local", num_cpus=args.local_cpus, include_dashboard=False)
    else:
        ray.init(address=args.address)
    print(f"ray_render: cluster {ray.cluster_resources()}", file=sys.stderr)
    start = time.monotonic()
    try:
        film = volpt.distributed.render(
            args.scene, args.spp, parts=args.parts, seed=args.seed, backend=args.backend,
            settings=settings, params=params, out=args.output, parts_dir=args.parts_dir,
            progress=True, num_cpus=args.num_cpus, max_retries=args.max_retries,
        )
    except volpt.VolptError as e:
        print(f"ray_render: {e}", file=sys.stderr)
        return 1
    finally:
        ray.shutdown()
    print(
        f"ray_render: {args.output}: {film.width}x{film.height}, samples {film.samples.start}.."
        f"{film.samples.stop}, {film.paths} paths in {time.monotonic() - start:.1f} s",
        file=sys.stderr,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
