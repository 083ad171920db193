"""The message types of a build: lcm-gen's Python modules (each type's
fingerprint, and the reference decoder) and lcm-gen's parse of the .lcm files,
stewart_types.txt (each type's fields, for the numpy layouts of decode.py).
Both are generated into <build>/lcmtypes/python (lcmtypes/CMakeLists.txt).
"""
from dataclasses import dataclass
import importlib.util
import os
import re
import sys

TYPES_FILE = "stewart_types.txt"

# numpy dtype of each LCM primitive as encoded (big-endian).
PRIMITIVES = {
    "int8_t": ">i1", "int16_t": ">i2", "int32_t": ">i4", "int64_t": ">i8",
    "float": ">f4", "double": ">f8", "byte": "u1", "boolean": ">i1",
}
INTEGERS = ("int8_t", "int16_t", "int32_t", "int64_t", "byte")

_STRUCT_LINE = re.compile(r"^struct (\S+) \[hash=")
_FIELD_LINE = re.compile(r"^\t(\S+)\s+(\w+)((?:\s*\[ \((?:const|var)\) \w+ \])*)\s*$")
_DIM = re.compile(r"\[ \((const|var)\) (\w+) \]")


@dataclass(frozen=True)
class Field:
    type: str  # an LCM primitive or "string"
    name: str
    dims: tuple  # per dimension: an int (fixed) or the name of an earlier integer field


@dataclass(frozen=True)
class MessageType:
    name: str  # "stewart.state_t"
    fields: tuple
    generated: type  # lcm-gen's class: its decode() is the reference


def parse_types_file(text):
    """{type name: (Field, ...)} from `lcm-gen --debug` output."""
    types, fields = {}, None
    for line in text.splitlines():
        struct_match = _STRUCT_LINE.match(line)
        if struct_match:
            fields = types.setdefault(struct_match.group(1), [])
            continue
        field_match = _FIELD_LINE.match(line)
        if not field_match or fields is None:
            if line.strip():
                raise ValueError(f"{TYPES_FILE}: unexpected line {line!r}")
            continue
        type_name, name, dims_text = field_match.groups()
        dims = tuple(int(v) if kind == "const" else v for kind, v in _DIM.findall(dims_text))
        fields.append(Field(type_name, name, dims))
    return {name: tuple(f) for name, f in types.items()}


def default_types_dir():
    """The first folder on sys.path (PYTHONPATH) holding the generated types,
    else this source tree's build/lcmtypes/python; None if neither has them."""
    here = os.path.dirname(os.path.abspath(__file__))
    candidates = list(sys.path) + [os.path.join(here, "..", "..", "..", "build", "lcmtypes",
                                                "python")]
    for folder in candidates:
        if folder and os.path.isfile(os.path.join(folder, TYPES_FILE)):
            return os.path.abspath(folder)
    return None


_loaded = {}


def load_types(types_dir=None):
    """{8-byte fingerprint: MessageType} for every type generated into `types_dir`."""
    types_dir = types_dir or default_types_dir()
    if types_dir is None:
        raise FileNotFoundError(
            f"no {TYPES_FILE}: pass types_dir=<build>/lcmtypes/python or put that folder on "
            "PYTHONPATH (it is made by building the target stewart_lcmtypes_python)")
    types_dir = os.path.abspath(types_dir)
    if types_dir not in _loaded:
        with open(os.path.join(types_dir, TYPES_FILE)) as f:
            parsed = parse_types_file(f.read())
        packages = {}
        by_fingerprint = {}
        for full_name, fields in parsed.items():
            package, _, short_name = full_name.rpartition(".")
            if package not in packages:
                packages[package] = _import_package(types_dir, package)
            generated = getattr(packages[package], short_name)
            by_fingerprint[generated._get_packed_fingerprint()] = MessageType(
                full_name, fields, generated)
        _loaded[types_dir] = by_fingerprint
    return _loaded[types_dir]


def _import_package(types_dir, package):
    # Under a private name: a notebook may load two builds' types side by side,
    # and sys.path stays as the user set it.
    init = os.path.join(types_dir, *package.split("."), "__init__.py")
    name = f"_stewart_log_types{len(sys.modules)}_{package.replace('.', '_')}"
    spec = importlib.util.spec_from_file_location(
        name, init, submodule_search_locations=[os.path.dirname(init)])
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # the package's relative imports look it up there
    spec.loader.exec_module(module)
    return module
