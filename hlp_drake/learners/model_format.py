"""The model-file format as data: ``models.json``'s fields and every array of ``models.npz`` by
name, dtype and shape, checked before any array is used.

Each learner declares its arrays (``STATE``: dtype and shape in its own dimensions, e.g. an SVM's
``support_vectors``: ``(n_support, n_features)``; see ``learners.state``); a dimension is a number
or a name every array of the learner that uses it must share, the feature code fixing some
(``FIXED``). The npz members'
headers are read first (within ``MAX_HEADER``), so a header declaring a huge array is refused
before anything is allocated; then the values are checked (indices in range, scales positive, every number within ``MAX_VALUE``),
and the sizes against the learner settings ``models.json`` declares (``check_declared``: e.g. as many
boosted trees as ``n_estimators``). Every damage is one ``ModelError``.

Trust: ``allow_pickle=False`` and this check make a model file plain data: loading one never runs
code. The SHA-256 in ``models.json`` only detects damage (anyone who edits the arrays can update it);
a user who must know the models are the ones they trained pins them with the SHA-256 of their
``models.json`` (which holds the arrays' digest): ``DecisionModels.load(directory, sha256=...)``,
or ``planner.models_sha256`` in a scenario.
"""

from __future__ import annotations

import hashlib
import io
import tokenize
import zipfile
import zlib
from math import comb
from typing import TYPE_CHECKING, Any

import numpy as np

from hlp_drake.errors import ModelError
from hlp_drake.features.arm import ARM_FEATURES
from hlp_drake.features.direction import DIRECTION_FEATURES
from hlp_drake.features.row_choice import ROW_CHOICE_FEATURES, ROW_CONTEXT_FEATURES
from hlp_drake.features.scene_features import GAP_FEATURES, OBJECT_FEATURES
from hlp_drake.features.segment import SEGMENT_FEATURES
from hlp_drake.files.documents import brief
from hlp_drake.learners.arm import CATEGORICAL as ARM_CATEGORICAL
from hlp_drake.learners.arm import ArmRegressor
from hlp_drake.learners.choice import RowChoiceClassifier
from hlp_drake.learners.direction import CATEGORICAL as DIRECTION_CATEGORICAL
from hlp_drake.learners.direction import DirectionClassifier
from hlp_drake.learners.encoding import N_DIRECTIONS
from hlp_drake.learners.novelty import SAMPLES as NOVELTY_SAMPLES
from hlp_drake.learners.state import Spec, prefixed
from hlp_drake.learners.svm import RbfSvmClassifier
from hlp_drake.learners.trees import LEAF

if TYPE_CHECKING:
    from hlp_drake.learners.models import LearnerSettings

MAX_MODEL_BYTES = 256 * 2**20
"""Largest ``models.npz`` read, bytes (the bundled one is ~0.5 MB)."""
MAX_ARRAY_BYTES = 64 * 2**20
"""Largest single array, bytes."""
MAX_HEADER = 4096
"""Longest .npy header read, bytes."""
MAX_DEPTH = 64
"""Deepest boosted tree."""
MAX_VALUE = 1e9
"""Largest magnitude of a stored number, and the inverse of the smallest scale (trained models
stay within 1e5; beyond, z-scores and kernels overflow)."""


def _encoded(features: int, categorical: int) -> int:
    """Columns after one-hot encoding ``categorical`` of ``features`` columns into directions."""
    return features - categorical + categorical * N_DIRECTIONS


FIXED = {
    "row.n_features": len(ROW_CHOICE_FEATURES),  # the row learner's and the novelty model's
    "direction.n_encoded": _encoded(len(DIRECTION_FEATURES), len(DIRECTION_CATEGORICAL)),
    "direction.n_pairs": comb(N_DIRECTIONS, 2),  # the one-vs-one direction pairs
    "direction.n_classes": N_DIRECTIONS,
    "arm.n_encoded": _encoded(len(ARM_FEATURES), len(ARM_CATEGORICAL)),
    "arm.n_outputs": 2,  # the arm's two angles
    "gap.n_features": len(GAP_FEATURES),
    "object.n_features": len(OBJECT_FEATURES),
    "segment.n_features": len(SEGMENT_FEATURES),
}
"""The learners' dimensions the feature code fixes (models of other sizes cannot plan)."""


def fixed_sizes(row_context: bool) -> dict[str, int]:
    """``FIXED`` for a row-choice classifier that reads the way the hand came too (``row_context``:
    ``ROW_CONTEXT_FEATURES``) or not."""
    return FIXED | {"row.n_features": len(ROW_CONTEXT_FEATURES if row_context else ROW_CHOICE_FEATURES)}


def expected_arrays(planner: str, row_learner: str) -> dict[str, Spec]:
    """Every array of a ``models.npz`` of ``planner`` ("rows" or "paper") by name: (dtype, shape), as
    each learner declares its arrays (``STATE``), its dimensions prefixed with its name."""
    arrays: dict[str, Spec] = {}
    if planner == "rows":
        arrays |= prefixed("row.", RowChoiceClassifier.state(row_learner))
    else:
        for name in ("gap", "object", "segment"):
            arrays |= prefixed(f"{name}.", RbfSvmClassifier.STATE)
    arrays |= prefixed("direction.", DirectionClassifier.STATE)
    arrays |= prefixed("arm.", ArmRegressor.STATE)
    arrays |= {"priors.start_arm": ("float64", (2,)), "priors.link_lengths": ("float64", (2,))}
    return arrays


def _header(member: Any) -> tuple[tuple[int, ...], np.dtype]:
    version = np.lib.format.read_magic(member)
    read = {(1, 0): np.lib.format.read_array_header_1_0, (2, 0): np.lib.format.read_array_header_2_0}.get(
        version
    )
    if read is None:
        raise ValueError(f"unknown .npy version {version}")
    try:
        shape, fortran, dtype = read(member, max_header_size=MAX_HEADER)
    except (SyntaxError, TypeError, RecursionError, tokenize.TokenError) as error:
        # numpy's header parser: literal_eval, then its Python 2 header filter (tokenize)
        raise ValueError(f"unreadable .npy header ({type(error).__name__})") from None
    if fortran:
        raise ValueError("Fortran-ordered array")
    return shape, dtype


def _check_shape(
    name: str, spec: Spec, shape: tuple[int, ...], dtype: np.dtype, sizes: dict[str, int]
) -> None:
    """Raise ``ValueError`` unless the array ``name`` has its learner's declared dtype and shape
    (``spec``), its named dimensions bound in ``sizes`` (the first array to use one binds it)."""
    kind, dims = spec
    if dtype != np.dtype(kind):
        raise ValueError(f"array {name!r} has dtype {dtype}, the format has {kind}")
    wanted = [dim if isinstance(dim, int) else sizes.get(dim) for dim in dims]
    if len(shape) != len(dims) or any(w is not None and w != size for w, size in zip(wanted, shape)):
        raise ValueError(f"array {name!r} has shape {shape}, expected {_declared(dims, sizes)}")
    for size, dim in zip(shape, dims):
        if size < 1:
            raise ValueError(
                f"array {name!r} has shape {shape}, expected {_declared(dims, sizes)}, none empty"
            )
        if isinstance(dim, str):
            sizes.setdefault(dim, size)
    if int(np.prod(shape, dtype=np.int64)) * dtype.itemsize > MAX_ARRAY_BYTES:
        raise ValueError(f"array {name!r} of shape {shape} is larger than {MAX_ARRAY_BYTES // 2**20} MiB")


def _declared(dims: tuple[int | str, ...], sizes: dict[str, int]) -> str:
    """A declared shape as the learner names it, with the sizes known: ``(n_support, n_features=5)``."""
    shown = [
        str(dim)
        if isinstance(dim, int)
        else dim.rsplit(".", 1)[-1] + (f"={sizes[dim]}" if dim in sizes else "")
        for dim in dims
    ]
    return f"({', '.join(shown)}{',' if len(shown) == 1 else ''})"


def read_arrays(
    payload: bytes, expected: dict[str, Spec], fixed: dict[str, int] | None = None
) -> dict[str, np.ndarray]:
    """The arrays of the npz ``payload``, each checked against ``expected`` (and the dimensions
    ``fixed``, default ``FIXED``) before it is read.

    Raises:
        ValueError: any damage (a member missing, unexpected or of another dtype or shape, a size
            inconsistent with the others, a broken zip or header).
    """
    sizes = dict(FIXED if fixed is None else fixed)
    try:
        with zipfile.ZipFile(io.BytesIO(payload)) as archive:
            infos = archive.infolist()
            names = [info.filename.removesuffix(".npy") for info in infos]
            if len(set(names)) != len(names):
                raise ValueError("an array is stored twice")
            unknown, missing = sorted(set(names) - set(expected)), sorted(set(expected) - set(names))
            if unknown or missing:
                raise ValueError(
                    f"arrays {brief(unknown)} are not in the format"
                    if unknown
                    else f"missing arrays {brief(missing)}"
                )
            for info, name in zip(infos, names):
                if info.file_size > MAX_ARRAY_BYTES + MAX_HEADER:
                    raise ValueError(f"array {name!r} is larger than {MAX_ARRAY_BYTES // 2**20} MiB")
                with archive.open(info) as member:
                    shape, dtype = _header(member)
                    _check_shape(name, expected[name], shape, dtype, sizes)
                    if member.tell() + int(np.prod(shape)) * dtype.itemsize != info.file_size:
                        raise ValueError(f"array {name!r} is truncated or padded")
            with np.load(io.BytesIO(payload), allow_pickle=False) as npz:
                return {name: npz[name] for name in expected}
    except (OSError, EOFError, zipfile.BadZipFile, zlib.error, NotImplementedError, RuntimeError) as error:
        raise ValueError(f"unreadable arrays ({type(error).__name__})") from None


def _range(name: str, values: np.ndarray, low: float, high: float) -> None:
    if values.size and (values.min() < low or values.max() > high):
        raise ValueError(f"array {name!r} has values outside [{low:g}, {high:g}]")


def check_values(arrays: dict[str, np.ndarray]) -> None:
    """Raise ``ValueError`` for values the planner cannot use (checked shapes assumed)."""
    for name, values in arrays.items():
        if values.dtype.kind == "f" and not np.all(np.isfinite(values)):
            raise ValueError(f"array {name!r} has non-finite values")
        if values.dtype.kind == "f":
            _range(name, values, -MAX_VALUE, MAX_VALUE)
    positive = [
        n
        for n in arrays
        if n.endswith(("scale", "gamma", "threshold", "y_std", "length_scale"))
        and not n.endswith("learner.threshold")
    ]
    for name in positive:
        _range(name, arrays[name], 1 / MAX_VALUE, MAX_VALUE)
    if "row.learner.feature" in arrays:
        nodes = arrays["row.learner.feature"].shape[1]
        features = len(arrays["row.novelty.mean"])  # its shape checked: the model's n_features
        _range("row.learner.feature", arrays["row.learner.feature"], 0, features - 1)
        for side in ("left", "right"):
            _range(f"row.learner.{side}", arrays[f"row.learner.{side}"], LEAF, nodes - 1)
        if np.any((arrays["row.learner.left"] == LEAF) != (arrays["row.learner.right"] == LEAF)):
            raise ValueError("array 'row.learner.left' and 'row.learner.right' disagree on the leaves")
        _range("row.learner.depth", arrays["row.learner.depth"], 0, min(MAX_DEPTH, nodes))
    if "row.novelty.neighbours" in arrays:
        _range(
            "row.novelty.neighbours", arrays["row.novelty.neighbours"], 1, len(arrays["row.novelty.points"])
        )
    for name in [n for n in arrays if n.endswith("classes")]:
        if len(np.unique(arrays[name])) != len(arrays[name]):
            raise ValueError(f"array {name!r} repeats a class")
    _range("arm.outputs", arrays["arm.outputs"], 0, FIXED["arm.n_outputs"])


def check_declared(arrays: dict[str, np.ndarray], settings: LearnerSettings) -> None:
    """Raise ``ValueError`` where the arrays' sizes disagree with the learner ``settings`` they were
    trained with (checked shapes assumed): the boosted trees' count (``n_estimators``), nodes and
    depth (``max_depth``), the arm's samples (``arm_max_samples``), the segment SVM's support
    vectors (two classes of ``segment_max_per_class``) and the novelty model's points."""
    sizes = []
    if "row.learner.feature" in arrays:
        trees, nodes = arrays["row.learner.feature"].shape
        if trees != settings.n_estimators:
            raise ValueError(
                f"array 'row.learner.feature' holds {trees} trees, the settings declare "
                f"n_estimators {settings.n_estimators}"
            )
        sizes.append(("row.learner.feature", nodes, 2 ** (settings.max_depth + 1) - 1, "nodes a tree"))
        sizes.append(("row.learner.depth", int(arrays["row.learner.depth"]), settings.max_depth, "levels"))
    if "row.novelty.points" in arrays:
        sizes.append(("row.novelty.points", len(arrays["row.novelty.points"]), NOVELTY_SAMPLES, "points"))
    if "segment.support_vectors" in arrays:
        limit = 2 * settings.segment_max_per_class
        sizes.append(("segment.support_vectors", len(arrays["segment.support_vectors"]), limit, "vectors"))
    sizes.append(("arm.train", len(arrays["arm.train"]), settings.arm_max_samples, "samples"))
    for name, size, limit, what in sizes:
        if size > limit:
            raise ValueError(
                f"array {name!r} holds {size} {what}, more than its learner settings allow ({limit})"
            )


def digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def check_pin(meta_bytes: bytes, sha256: str | None, where: str) -> None:
    """Refuse ``models.json`` (its bytes) unless its SHA-256 is ``sha256`` (when one is given)."""
    if sha256 is None or sha256 == "":
        return
    if digest(meta_bytes) != sha256.strip().lower():
        raise ModelError(
            f"{where}: SHA-256 {digest(meta_bytes)[:16]}... is not the pinned {brief(sha256)} "
            "(these are not the trusted models)"
        )
