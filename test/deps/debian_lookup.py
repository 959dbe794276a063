"""What provides a thing on this Debian machine: the file behind a Python module, a command or a
ROS executable, its Debian package, the package's priority, and the ROS packages it belongs to."""

from __future__ import annotations

import functools
import importlib.util
import os
import re
import shutil
import subprocess
from pathlib import Path

# Where Debian installs programs (a PATH lookup, without /usr/local and the like).
SYSTEM_PATH = "/usr/sbin:/usr/bin:/sbin:/bin"


@functools.lru_cache(maxsize=None)
def providing_file(kind, name):
    """The installed file behind a use, or None."""
    if kind == "python module":
        try:
            spec = importlib.util.find_spec(name)
        except (ImportError, ValueError):
            spec = None
        if spec is None:
            return None
        if spec.origin and spec.origin not in ("built-in", "frozen", "namespace"):
            return spec.origin
        locations = list(spec.submodule_search_locations or [])
        return locations[0] if locations else None
    if kind == "command":
        path = shutil.which(name, path=SYSTEM_PATH)
        return os.path.realpath(path) if path else None
    if kind == "ROS executable":
        pkg, executable = name.split("/", 1)
        for directory in (f"/usr/lib/{pkg}", f"/usr/share/{pkg}/scripts", "/usr/bin"):
            candidate = Path(directory) / executable
            if candidate.exists():
                return str(candidate)
        return None
    raise ValueError(kind)


@functools.lru_cache(maxsize=None)
def debian_package(path):
    out = subprocess.run(["dpkg-query", "-S", path], capture_output=True, text=True)
    if out.returncode != 0:
        # dpkg knows the unresolved path (e.g. /bin/x when /bin -> usr/bin).
        alternative = re.sub(r"^/usr/", "/", path)
        out = subprocess.run(["dpkg-query", "-S", alternative], capture_output=True, text=True)
        if out.returncode != 0:
            return None
    return out.stdout.split(":")[0].split(",")[0].strip()


@functools.lru_cache(maxsize=None)
def priority(package):
    out = subprocess.run(["dpkg-query", "-W", "-f=${Priority}", package], capture_output=True,
                         text=True)
    return out.stdout.strip()


@functools.lru_cache(maxsize=None)
def ros_packages_in(package):
    """The ROS packages a Debian package belongs to: those whose /usr/share/NAME/package.xml it
    installs, else those of the installed packages built from the same source (Debian ships a
    ROS package's package.xml in one of them, e.g. rospack's in librospack-dev, not in
    rospack-tools)."""
    def shipped(name):
        out = subprocess.run(["dpkg-query", "-L", name], capture_output=True, text=True)
        return set(re.findall(r"^/usr/share/([^/\n]+)/package\.xml$", out.stdout, re.M))

    own = shipped(package)
    if own:
        return sorted(own)
    out = subprocess.run(["dpkg-query", "-W", "-f=${Package}\t${Source}\t${Status}\n"],
                         capture_output=True, text=True)
    sources = {}
    for line in out.stdout.split("\n"):
        fields = line.split("\t")
        if len(fields) == 3 and fields[2].endswith(" installed"):
            sources[fields[0]] = fields[1].split(" ")[0] or fields[0]
    source = sources.get(package, package)
    siblings = [name for name, src in sources.items() if src == source and name != package]
    return sorted(set().union(*(shipped(name) for name in siblings))) if siblings else []


@functools.lru_cache(maxsize=None)
def reverse_dependencies(package):
    """The installed packages that depend on `package` directly (e.g. imagemagick on
    imagemagick-6.q16, which provides its programs)."""
    out = subprocess.run(["dpkg-query", "-W", "-f=${Package}\t${Depends}\n"],
                         capture_output=True, text=True)
    users = set()
    for line in out.stdout.split("\n"):
        name, _, depends = line.partition("\t")
        alternatives = re.split(r"[,|]", depends)
        if any(a.split("(")[0].split(":")[0].strip() == package for a in alternatives):
            users.add(name)
    return frozenset(users)
