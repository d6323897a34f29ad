#!/usr/bin/env python3
"""Compiles and links bench/arm/aerie_cost.cpp against an existing build directory.

usage: build_driver.py BUILD_DIR OUT_BINARY

The driver is not a CMake target (bench/arm has no CMakeLists.txt, so no build picks it
up). Its compile flags are the union of those CMake used for the four nodes' main.cpp
(compile_commands.json: include directories, definitions, the compiler and its --sysroot),
and its link line is the four nodes' own link lines put one after the other (`ninja -t
commands`), so it links exactly the static libraries and shared objects the node binaries
link, in the build directory's configuration (arm64, armhf or the host's `air`).
"""
import json
import os
import shlex
import subprocess
import sys

NODES = {  # node binary -> its main.cpp
    "aerie-track": "air/track/node/main.cpp",
    "aerie-vo": "air/stereo/node/main.cpp",
    "aerie-capture": "air/capture/main.cpp",
    "aerie-control": "air/control/main.cpp",
}


def die(msg):
    sys.exit(f"build_driver.py: {msg}")


def main():
    if len(sys.argv) != 3:
        die("usage: build_driver.py BUILD_DIR OUT_BINARY")
    build = os.path.abspath(sys.argv[1])
    out = os.path.abspath(sys.argv[2])
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    src = os.path.join(root, "bench/arm/aerie_cost.cpp")
    ccj = os.path.join(build, "compile_commands.json")
    if not os.path.exists(ccj):
        die(f"{ccj} is missing: configure {build} first (cmake --preset ...)")
    entries = json.load(open(ccj))

    compiler, flags = None, []
    for main in NODES.values():
        e = next((e for e in entries if e["file"].endswith("/" + main)), None)
        if e is None:
            die(f"{main} is not in {ccj}")
        toks = shlex.split(e["command"]) if "command" in e else list(e["arguments"])
        compiler = compiler or toks[0]
        i = 1
        while i < len(toks):
            t = toks[i]
            if t in ("-o", "-c"):
                i += 2
                continue
            if t in ("-isystem", "-I", "-D", "-include"):
                pair = t + " " + toks[i + 1]
                if pair not in flags:
                    flags.append(pair)
                i += 2
                continue
            if t not in flags:
                flags.append(t)
            i += 1
    os.makedirs(os.path.dirname(out), exist_ok=True)
    obj = out + ".o"
    cmd = [compiler] + [x for f in flags for x in shlex.split(f)] + ["-o", obj, "-c", src]
    print("+ " + " ".join(shlex.quote(c) for c in cmd), flush=True)
    subprocess.run(cmd, cwd=build, check=True)

    link_front, libs = None, []
    for node, main in NODES.items():
        r = subprocess.run(["ninja", "-C", build, "-t", "commands", node], capture_output=True, text=True)
        if r.returncode != 0:
            die(f"ninja -t commands {node} failed in {build}: {r.stderr.strip()}")
        line = r.stdout.strip().splitlines()[-1]
        toks = shlex.split(line)
        toks = [t for t in toks if t not in (":", "&&")]
        try:
            o = toks.index("-o")
        except ValueError:
            die(f"no link line for {node}: {line[:200]}")
        front = [t for t in toks[:o] if not t.endswith("main.cpp.o")]
        link_front = link_front or front
        for t in toks[o + 2:]:
            if not t.endswith(".o"):
                libs.append(t)
        lib_missing = [t for t in toks[o + 2:] if t.endswith(".a") and not os.path.exists(os.path.join(build, t))]
        if lib_missing:
            die(f"{build}: {', '.join(lib_missing[:3])} not built: build the node binaries first "
                f"(ninja -C {build} aerie-track aerie-vo aerie-capture aerie-control)")
    cmd = link_front + [obj, "-o", out] + libs
    print("+ " + " ".join(shlex.quote(c) for c in cmd[:6]) + f" ... ({len(libs)} libraries)", flush=True)
    subprocess.run(cmd, cwd=build, check=True)


if __name__ == "__main__":
    main()
