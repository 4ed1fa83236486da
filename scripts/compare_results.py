"""Compare two petsc_rod result files, every dataset and every attribute of every group.

    python scripts/compare_results.py A.h5 B.h5 [--rtol R]

Prints one line per difference: its name, and for numbers the largest absolute
difference max|a - b| and the largest relative one max(|a - b| / max(|a|, |b|)); a
dataset or an attribute present in one file only, or with another shape or type, is a
difference of its own. Two values agree when |a - b| <= R max(|a|, |b|) elementwise
(R = 0 by default: bit for bit, NaN equal to NaN). Exit 0 when everything agrees, 1
otherwise, 2 when a file cannot be read.

Ignored, because they must differ between two runs of the same scene (docs/output.md,
io/results.py, io/provenance.py): the attributes ``written`` (the date a group was
written) and ``wall_time`` (seconds), the datasets ``history/wall_time``, the root's
``commit`` and ``version`` (which program wrote the file), and the file's own path:
the attribute ``output`` of the group ``parameters``, and that path inside the option
texts ``options`` and ``options_in_effect`` (compared with it replaced by ``<output>``).
"""

import argparse
import sys

import h5py
import numpy as np

IGNORED_ATTRIBUTES = {"written", "wall_time"}
IGNORED_ROOT_ATTRIBUTES = {"commit", "version"}
IGNORED_PARAMETERS = {"output"}
PATH_TEXTS = {"options", "options_in_effect"}
IGNORED_DATASET_NAMES = {"wall_time"}          # only inside a group ``history``
OWN_PATH = "<output>"


def own_path(handle):
    """The path the file was written to (``parameters/output``), or None."""
    group = handle.get("parameters")
    if not isinstance(group, h5py.Group) or "output" not in group.attrs:
        return None
    return _text(group.attrs["output"]) or None


def _text(value):
    value = value.decode() if isinstance(value, bytes) else value
    return value if isinstance(value, str) else None


def ignored_attribute(group_name, key):
    if key in IGNORED_ATTRIBUTES:
        return True
    if group_name == "/" and key in IGNORED_ROOT_ATTRIBUTES:
        return True
    return group_name.rstrip("/").split("/")[-1] == "parameters" and key in IGNORED_PARAMETERS


def ignored_dataset(name):
    parts = name.strip("/").split("/")
    return len(parts) >= 2 and parts[-2] == "history" and parts[-1] in IGNORED_DATASET_NAMES


def collect(handle):
    """({dataset name: h5py.Dataset}, {group name: {attribute: value}}) of a whole file,
    without the ignored entries; a path text has the file's own path replaced."""
    datasets, attributes = {}, {}
    path = own_path(handle)

    def attributes_of(name, obj):
        values = {}
        for key, value in obj.attrs.items():
            if ignored_attribute(name, key):
                continue
            text = _text(value)
            if key in PATH_TEXTS and text is not None and path:
                value = text.replace(path, OWN_PATH)
            values[key] = value
        attributes[name] = values

    def visit(name, obj):
        full = "/" + name
        if isinstance(obj, h5py.Dataset):
            if not ignored_dataset(full):
                datasets[full] = obj
                attributes_of(full, obj)
        else:
            attributes_of(full, obj)

    attributes_of("/", handle)
    handle.visititems(visit)
    return datasets, attributes


def compare_values(name, a, b, rtol):
    """A line describing how ``a`` and ``b`` differ, or None when they agree."""
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape:
        return f"{name}: shape {a.shape} != {b.shape}"
    numeric = (np.issubdtype(a.dtype, np.number) or a.dtype == bool) and \
              (np.issubdtype(b.dtype, np.number) or b.dtype == bool)
    if not numeric:
        if a.dtype.kind != b.dtype.kind and not (a.dtype.kind in "SUO" and b.dtype.kind in "SUO"):
            return f"{name}: type {a.dtype} != {b.dtype}"
        same = np.array_equal(np.vectorize(_plain, otypes=[object])(a),
                              np.vectorize(_plain, otypes=[object])(b)) if a.size else True
        return None if same else f"{name}: text differs: {_short(a)} != {_short(b)}"
    a, b = a.astype(float), b.astype(float)
    both_nan = np.isnan(a) & np.isnan(b)
    with np.errstate(invalid="ignore"):
        difference = np.where(both_nan, 0.0, np.abs(a - b))
        scale = np.maximum(np.abs(a), np.abs(b))
        same_inf = (a == b)                          # equal infinities give inf - inf = nan
        difference = np.where(same_inf, 0.0, difference)
        difference = np.where(np.isnan(difference), np.inf, difference)
        relative = np.where(difference == 0, 0.0,
                            difference / np.where(scale > 0, scale, np.inf))
        relative = np.where((difference > 0) & ~(scale > 0), np.inf, relative)
        agree = difference <= rtol * np.where(np.isfinite(scale), scale, 0.0)
    if agree.all():
        return None
    return (f"{name}: max abs diff {difference.max():.3e}, max rel diff {relative.max():.3e}"
            f" ({int((~agree).sum())} of {agree.size} values differ)")


def _plain(value):
    return value.decode() if isinstance(value, bytes) else value


def _short(array, width=80):
    text = " ".join(str(array).split())
    return text if len(text) <= width else text[:width] + "..."


def compare_files(path_a, path_b, rtol=0.0):
    """Every difference between result files ``path_a`` and ``path_b``, as lines."""
    lines = []
    with h5py.File(path_a, "r") as file_a, h5py.File(path_b, "r") as file_b:
        datasets_a, attributes_a = collect(file_a)
        datasets_b, attributes_b = collect(file_b)
        for name in sorted(set(datasets_a) | set(datasets_b)):
            if name not in datasets_b:
                lines.append(f"{name}: dataset only in {path_a}")
            elif name not in datasets_a:
                lines.append(f"{name}: dataset only in {path_b}")
            else:
                line = compare_values(name, datasets_a[name][()], datasets_b[name][()], rtol)
                if line:
                    lines.append(line)
        for group in sorted(set(attributes_a) | set(attributes_b)):
            if group not in attributes_a or group not in attributes_b:
                if group not in datasets_a and group not in datasets_b:
                    lines.append(f"{group}: group only in "
                                 f"{path_a if group in attributes_a else path_b}")
                continue
            values_a, values_b = attributes_a[group], attributes_b[group]
            for key in sorted(set(values_a) | set(values_b)):
                name = f"{group.rstrip('/')}@{key}" if group != "/" else f"/@{key}"
                if key not in values_b:
                    lines.append(f"{name}: attribute only in {path_a}")
                elif key not in values_a:
                    lines.append(f"{name}: attribute only in {path_b}")
                else:
                    line = compare_values(name, values_a[key], values_b[key], rtol)
                    if line:
                        lines.append(line)
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("a")
    parser.add_argument("b")
    parser.add_argument("--rtol", type=float, default=0.0,
                        help="relative tolerance (default 0: bit-identical)")
    args = parser.parse_args(argv)
    try:
        lines = compare_files(args.a, args.b, args.rtol)
    except (OSError, KeyError) as error:
        print(f"compare_results: error: {error}", file=sys.stderr)
        return 2
    for line in lines:
        print(line)
    print(f"{args.a} vs {args.b}: " + (f"{len(lines)} difference(s)" if lines else
                                        f"identical (rtol {args.rtol:g})"))
    return 1 if lines else 0


if __name__ == "__main__":
    sys.exit(main())
