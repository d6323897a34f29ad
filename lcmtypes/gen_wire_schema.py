#!/usr/bin/env python3
"""Wire schema of the message catalogue, for bounded decoding (docs/messages.md).

Reads lcmtypes/*.lcm and the sanity caps of decode_limits.txt and writes a C++ file with one
aerie::bus::wire::Type table per struct (fields in wire order, array dimensions, caps) and
the catalogue of top-level types with their lcm-gen getHash(). common/bus/wire.cpp walks a
payload along these tables before any lcm-gen decoder sees it.

Parses the subset of the LCM IDL the catalogue uses: one package per file, structs, the
primitive types, string, fixed and variable multi-dimensional arrays, nested structs
(same or qualified package), constants (skipped), // and /* */ comments.

usage: gen_wire_schema.py --limits decode_limits.txt -o wire_schema.cpp a.lcm b.lcm ...
"""
import argparse
import re
import sys

PRIMITIVES = {  # LCM type -> wire::Kind
    "int8_t": "Int8", "int16_t": "Int16", "int32_t": "Int32", "int64_t": "Int64",
    "float": "Float", "double": "Double", "boolean": "Boolean", "byte": "Byte", "string": "String",
}
INTEGERS = {"int8_t", "int16_t", "int32_t", "int64_t"}
MIN_BYTES = {"int8_t": 1, "int16_t": 2, "int32_t": 4, "int64_t": 8, "float": 4, "double": 8,
             "boolean": 1, "byte": 1, "string": 5}  # string: int32 length + the NUL at least
TOKEN = re.compile(r"[A-Za-z_][\w.]*|-?[\w.+-]+|\S")


class IdlError(Exception):
    pass


class Tokens:
    def __init__(self, text, origin):
        text = re.sub(r"//[^\n]*|/\*.*?\*/", " ", text, flags=re.S)
        self.toks, self.i, self.origin = TOKEN.findall(text), 0, origin

    def peek(self):
        return self.toks[self.i] if self.i < len(self.toks) else None

    def next(self, expected=None):
        tok = self.peek()
        if tok is None or (expected is not None and tok != expected):
            raise IdlError(f"{self.origin}: expected {expected or 'more'}, found {tok!r}")
        self.i += 1
        return tok


def parse(path):
    """[(full_name, [(field, type, [dim: int | str])])] of one .lcm file."""
    with open(path, encoding="utf-8") as f:
        t = Tokens(f.read(), path)
    t.next("package")
    pkg = t.next()
    t.next(";")
    structs = []
    while t.peek() is not None:
        t.next("struct")
        name = f"{pkg}.{t.next()}"
        t.next("{")
        fields = []
        while t.peek() != "}":
            if t.peek() == "const":
                while t.next() != ";":
                    pass
                continue
            typ = t.next()
            if typ not in PRIMITIVES and "." not in typ:
                typ = f"{pkg}.{typ}"
            while True:
                field, dims = t.next(), []
                while t.peek() == "[":
                    t.next("[")
                    d = t.next()
                    dims.append(int(d) if d.isdigit() else d)
                    t.next("]")
                fields.append((field, typ, dims))
                if t.next() == ";":
                    break
        t.next("}")
        structs.append((name, fields))
    return structs


def read_limits(path):
    """{"pkg.type.field": cap} from lines '<pkg>.<type>.<field> <max>  # why'."""
    limits = {}
    with open(path, encoding="utf-8") as f:
        for n, line in enumerate(f, 1):
            words = line.split("#", 1)[0].split()
            if not words:
                continue
            if len(words) != 2 or not words[1].isdigit():
                raise IdlError(f"{path}:{n}: expected '<package>.<type>.<field> <max>'")
            limits[words[0]] = int(words[1])
    return limits


def check(types, limits, limits_path):
    """The catalogue must be one the validator can walk; every cap must name a count or string."""
    counts = set()
    for name, fields in types.items():
        seen = {}
        for field, typ, dims in fields:
            if typ not in PRIMITIVES and typ not in types:
                raise IdlError(f"{name}.{field}: unknown type {typ}")
            for d in dims:
                if isinstance(d, str):
                    if seen.get(d) not in INTEGERS:
                        raise IdlError(f"{name}.{field}: dimension {d} is not an earlier integer field")
                    counts.add(f"{name}.{d}")
            seen[field] = typ if not dims else None
    for key in limits:
        name, _, field = key.rpartition(".")
        typ = {f: t for f, t, d in types.get(name, []) if not d}.get(field)
        if key not in counts and typ != "string":
            raise IdlError(f"{limits_path}: {key} is neither an array count nor a string field")


def ordered(types):
    """Nested types before the types that hold them (the tables refer to them)."""
    out, state = [], {}

    def visit(name):
        if state.get(name) == "done":
            return
        if state.get(name) == "visiting":
            raise IdlError(f"{name}: recursive types are not supported")
        state[name] = "visiting"
        for _, typ, _ in types[name]:
            if typ in types:
                visit(typ)
        state[name] = "done"
        out.append(name)

    for name in sorted(types):
        visit(name)
    return out


def min_bytes(typ, types, memo):
    if typ in PRIMITIVES:
        return MIN_BYTES[typ]
    if typ not in memo:
        memo[typ] = sum(min_bytes(t, types, memo) * fixed_elements(d) for _, t, d in types[typ])
    return memo[typ]


def fixed_elements(dims):
    n = 1
    for d in dims:
        n *= d if isinstance(d, int) else 0
    return n


def emit(types, limits):
    ident = lambda name: name.replace(".", "_")  # noqa: E731
    memo = {}
    out = [
        "// Generated by lcmtypes/gen_wire_schema.py from lcmtypes/*.lcm and lcmtypes/decode_limits.txt:",
        "// do not edit. The wire layout of every message type, walked by common/bus/wire.cpp.",
        '#include "common/bus/wire.hpp"',
        "",
    ]
    out += [f"#include <{n.replace('.', '/')}.hpp>" for n in sorted(types)]
    out += ["", "namespace aerie::bus::wire {", "namespace {", ""]
    for name in ordered(types):
        fields, cid = types[name], ident(name)
        index = {f: i for i, (f, _, _) in enumerate(fields)}
        rows = []
        for field, typ, dims in fields:
            dim_name = "{}"
            if dims:
                dim_name = f"{cid}_{field}_dims"
                ds = ", ".join(f"{{{d}, -1}}" if isinstance(d, int) else f"{{0, {index[d]}}}" for d in dims)
                out.append(f"constexpr Dim {dim_name}[] = {{{ds}}};")
            kind = PRIMITIVES.get(typ, "Struct")
            nested = f"&{ident(typ)}" if typ in types else "nullptr"
            cap = limits.get(f"{name}.{field}")
            rows.append(f'    {{"{field}", Kind::{kind}, {nested}, {dim_name}, {cap if cap is not None else "kNoCap"}}},')
        out.append(f"static_assert({len(fields)} <= kMaxFields, \"{name} has too many fields\");")
        out.append(f"constexpr Field {cid}_fields[] = {{")
        out += rows
        out.append("};")
        out.append(f'constexpr Type {cid}{{"{name}", {cid}_fields, {min_bytes(name, types, memo)}}};')
        out.append("")
    out.append("constexpr Entry kCatalogue[] = {")
    out += [f"    {{&{ident(n)}, &::{n.replace('.', '::')}::getHash}}," for n in sorted(types)]
    out += ["};", "", "}  // namespace", "", "std::span<const Entry> catalogue() { return kCatalogue; }", "",
            "}  // namespace aerie::bus::wire", ""]
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--limits", required=True)
    ap.add_argument("-o", "--output", required=True)
    ap.add_argument("lcm", nargs="+")
    args = ap.parse_args()
    try:
        types = {}
        for path in args.lcm:
            for name, fields in parse(path):
                if name in types:
                    raise IdlError(f"{path}: {name} defined twice")
                types[name] = fields
        limits = read_limits(args.limits)
        check(types, limits, args.limits)
        text = emit(types, limits)
    except (IdlError, ValueError, OSError) as e:
        sys.exit(f"gen_wire_schema.py: {e}")
    with open(args.output, "w", encoding="utf-8") as f:
        f.write(text)


if __name__ == "__main__":
    main()
