"""The BlazePose landmark model: fetch, convert, verify and cache.

No model hub is reachable from where the project runs, but MediaPipe's wheel
on the package index carries ``pose_landmark_full.tflite``.  :func:`fetch_model`
downloads that wheel with pip (``--no-deps``; only the model file is used),
checks the file's sha256, converts it to ONNX with ``tflite2onnx`` 0.4.1,
verifies the result with onnxruntime and stores it in the user cache folder
with a manifest of hashes.  :func:`resolve_model` is the one place that decides
which ONNX file is used: ``--model PATH`` > ``$C2N_POSE_MODEL`` > the cache
(fetched automatically on first use).

``tflite2onnx`` 0.4.1 has one bug that this model triggers: when two ``Pad``
operators share the same paddings constant, ``Padding.transform`` rewrites the
constant in place once per operator, so the second pass sees the already
flattened ONNX pads and fails (``IndexError: too many indices``).
:func:`patched_tflite2onnx` makes that transform idempotent for the duration of
a conversion; see :func:`_idempotent_pad_transform`.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import os
import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

import numpy as np

from ..atomic import atomic_path, write_text
from ..errors import ModelError

__all__ = [
    "INPUT_SHAPE",
    "MEDIAPIPE_VERSION",
    "OUTPUT_SHAPES",
    "TFLITE_MEMBER",
    "TFLITE_SHA256",
    "cache_dir",
    "cached_model_path",
    "cached_tflite_path",
    "convert_tflite",
    "fetch_model",
    "patched_tflite2onnx",
    "resolve_model",
    "sha256_file",
    "verify_onnx",
]

logger = logging.getLogger(__name__)

MEDIAPIPE_VERSION = "0.10.14"
TFLITE_MEMBER = "mediapipe/modules/pose_landmark/pose_landmark_full.tflite"
TFLITE_SHA256 = "e9a5c5cb17f736fafd4c2ec1da3b3d331d6edbe8a0d32395855aeb2cdfd64b9f"
ONNX_NAME = "pose_landmark_full.onnx"
MANIFEST_NAME = "manifest.json"
ENV_MODEL = "C2N_POSE_MODEL"
ENV_CACHE = "C2N_CACHE_DIR"

#: Model input, NCHW RGB in [0, 1].
INPUT_SHAPE = (1, 3, 256, 256)
#: Model outputs in order: landmarks 39×5, pose flag, segmentation,
#: heatmaps 39×64×64 (logits), world landmarks 39×3 (metres).
OUTPUT_SHAPES = ((1, 195), (1, 1), (1, 1, 256, 256), (1, 39, 64, 64), (1, 117))

_HOW_TO_FIX = (
    "Run `c2n models fetch` on a machine that can reach the Python package index "
    f"(it runs `pip download --no-deps mediapipe=={MEDIAPIPE_VERSION}`), or "
    "`c2n models fetch --wheel mediapipe-{v}-*.whl` with a wheel copied by hand, "
    f"or set {ENV_MODEL}=/path/to/{ONNX_NAME} (or pass --model PATH)."
).replace("{v}", MEDIAPIPE_VERSION)


def sha256_file(path) -> str:
    """Hex sha256 of a file, read in 1 MiB blocks."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def cache_dir() -> Path:
    """The model cache folder (``$C2N_CACHE_DIR`` or ``platformdirs.user_cache_dir``)."""
    env = os.environ.get(ENV_CACHE)
    if env:
        return Path(env)
    import platformdirs

    return Path(platformdirs.user_cache_dir("capture2notation"))


def cached_model_path(cache: Path | None = None) -> Path:
    """Where the converted ONNX model lives in the cache (it may not exist yet)."""
    return Path(cache or cache_dir()) / ONNX_NAME


def cached_tflite_path(cache: Path | None = None) -> Path:
    """Where the source TFLite model is kept in the cache."""
    return Path(cache or cache_dir()) / Path(TFLITE_MEMBER).name


def _read_manifest(cache: Path) -> dict | None:
    path = cache / MANIFEST_NAME
    if not path.exists():
        return None
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError) as exc:
        logger.warning("ignoring unreadable model manifest %s: %s", path, exc)
        return None


def _cache_is_valid(cache: Path) -> bool:
    onnx_path = cached_model_path(cache)
    manifest = _read_manifest(cache)
    if manifest is None or not onnx_path.exists():
        return False
    return manifest.get("onnx_sha256") == sha256_file(onnx_path)


def resolve_model(path=None, *, fetch: bool = True) -> Path:
    """Return the ONNX pose model to use, fetching it on first use.

    Parameters
    ----------
    path : str or Path, optional
        Explicit model file (``--model PATH``); wins over everything else.
    fetch : bool
        Fetch and convert the model when neither `path`, ``$C2N_POSE_MODEL``
        nor a valid cached copy exists.

    Returns
    -------
    Path
        An existing ``.onnx`` file.

    Raises
    ------
    ModelError
        The given file does not exist, or no model is cached and fetching is
        disabled or impossible (the message says what to run or set).
    """
    if path is None and os.environ.get(ENV_MODEL):
        path = os.environ[ENV_MODEL]
        source = f"${ENV_MODEL}"
    else:
        source = "--model"
    if path is not None:
        path = Path(path)
        if not path.is_file():
            raise ModelError(f"pose model {path} (from {source}) does not exist; expected an ONNX file")
        return path
    cache = cache_dir()
    if _cache_is_valid(cache):
        return cached_model_path(cache)
    if not fetch:
        raise ModelError(f"no pose model in the cache {cache}. {_HOW_TO_FIX}")
    logger.warning(
        "BlazePose model not cached yet: fetching mediapipe==%s from the package index "
        "and converting it to ONNX (one time, ~35 MB) into %s",
        MEDIAPIPE_VERSION,
        cache,
    )
    return fetch_model(cache=cache)


def _download_wheel(dest: Path) -> Path:
    """pip-download the MediaPipe wheel into `dest`; return the wheel path."""
    # One fixed manylinux wheel whatever the host: the model inside is the
    # same in every wheel, and pinning the platform keeps the fetch identical
    # on macOS / Windows CI runners.
    cmd = [
        sys.executable, "-m", "pip", "download", "--no-deps", "--only-binary=:all:",
        "--platform", "manylinux2014_x86_64", "--python-version", "3.11",
        "--implementation", "cp", "--abi", "cp311",
        "--disable-pip-version-check", "--no-input", "--progress-bar", "off",
        f"mediapipe=={MEDIAPIPE_VERSION}", "-d", str(dest),
    ]  # fmt: skip
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=900, check=False)
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise ModelError(f"could not run pip to download mediapipe=={MEDIAPIPE_VERSION}: {exc}. {_HOW_TO_FIX}") from exc
    wheels = sorted(dest.glob("mediapipe-*.whl"))
    if proc.returncode != 0 or not wheels:
        tail = (proc.stderr or proc.stdout).strip().splitlines()[-3:]
        raise ModelError(
            f"pip could not download mediapipe=={MEDIAPIPE_VERSION} (exit {proc.returncode}: "
            f"{' | '.join(tail)}). {_HOW_TO_FIX}"
        )
    return wheels[0]


def _extract_tflite(wheel: Path, dest: Path) -> Path:
    """Extract the landmark model from the wheel and check its sha256."""
    try:
        with zipfile.ZipFile(wheel) as zf:
            data = zf.read(TFLITE_MEMBER)
    except (OSError, KeyError, zipfile.BadZipFile) as exc:
        raise ModelError(
            f"{wheel}: cannot read {TFLITE_MEMBER} ({exc}); expected a mediapipe=={MEDIAPIPE_VERSION} wheel"
        ) from exc
    digest = hashlib.sha256(data).hexdigest()
    if digest != TFLITE_SHA256:
        raise ModelError(f"{wheel}: {TFLITE_MEMBER} has sha256 {digest}, expected {TFLITE_SHA256}")
    out = dest / Path(TFLITE_MEMBER).name
    out.write_bytes(data)
    return out


def fetch_model(cache=None, *, wheel=None, force: bool = False) -> Path:
    """Download, convert, verify and cache the BlazePose full landmark model.

    Parameters
    ----------
    cache : str or Path, optional
        Cache folder (default :func:`cache_dir`).
    wheel : str or Path, optional
        A ``mediapipe-0.10.14-*.whl`` already on disk (no download).
    force : bool
        Rebuild even when a valid cached model exists.

    Returns
    -------
    Path
        The cached ONNX model.
    """
    cache = Path(cache or cache_dir())
    if not force and _cache_is_valid(cache):
        return cached_model_path(cache)
    cache.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="c2n-model-") as tmp:
        tmp = Path(tmp)
        wheel_path = Path(wheel) if wheel is not None else _download_wheel(tmp)
        if not wheel_path.is_file():
            raise ModelError(f"wheel {wheel_path} does not exist; expected mediapipe-{MEDIAPIPE_VERSION}-*.whl")
        tflite_path = _extract_tflite(wheel_path, tmp)
        onnx_tmp = tmp / ONNX_NAME
        convert_tflite(tflite_path, onnx_tmp)
        verify_onnx(onnx_tmp)
        target = cached_model_path(cache)
        with atomic_path(target) as part:
            shutil.copyfile(onnx_tmp, part)
        # Keep the source model too (6 MB): re-conversion needs no download.
        with atomic_path(cached_tflite_path(cache)) as part:
            shutil.copyfile(tflite_path, part)
    tflite2onnx = _converter()
    manifest = {
        "model": ONNX_NAME,
        "source": f"mediapipe=={MEDIAPIPE_VERSION} wheel, {TFLITE_MEMBER}",
        "tflite_sha256": TFLITE_SHA256,
        "onnx_sha256": sha256_file(target),
        "converter": f"tflite2onnx=={tflite2onnx.__version__} with capture2notation's shared-Pad fix",
    }
    write_text(cache / MANIFEST_NAME, json.dumps(manifest, indent=1) + "\n")
    logger.warning("BlazePose model ready: %s", target)
    return target


# --------------------------------------------------------------------------
# tflite2onnx 0.4.1 shared-Pad-constant fix
# --------------------------------------------------------------------------


def _idempotent_pad_transform(original):
    """Wrap ``tflite2onnx.op.padding.Padding.transform`` so it can run twice.

    The original converts the paddings tensor *in place* from TFLite's
    ``(rank, 2)`` (begin, end per axis) to ONNX's flat ``[begins..., ends...]``.
    A paddings constant shared by two Pad operators is one tensor object, so
    the second operator receives the already converted flat array and fails.
    The wrapper keeps the original TFLite pads on the tensor the first time and
    restores them before every call, so each call converts from the source
    and yields the same result; if two sharers need different layouts (which
    would need two tensors), it raises instead of writing a wrong model.
    """

    def transform(self):
        pads = self.inputs[1]
        saved = getattr(pads, "_c2n_tflite_pads", None)
        if saved is None:
            pads._c2n_tflite_pads = (np.array(pads.data, copy=True), list(pads.shape))
        else:
            done = np.array(pads.data, copy=True)
            pads.data, pads.shape = saved[0].copy(), list(saved[1])
        original(self)
        if saved is not None and not np.array_equal(done, pads.data):
            raise ModelError(
                f"tflite2onnx: paddings constant {pads.name} is shared by Pad operators "
                "that need different layouts; cannot convert this model"
            )

    transform.__wrapped__ = original
    return transform


@contextlib.contextmanager
def patched_tflite2onnx():
    """Apply the shared-Pad fix to ``tflite2onnx`` for the duration of a block."""
    try:
        from tflite2onnx.op.padding import Padding
    except ImportError as exc:
        raise ModelError(
            "tflite2onnx is not installed; `pip install tflite2onnx==0.4.1` "
            f"(needed once to convert the model). {_HOW_TO_FIX}"
        ) from exc
    original = Padding.transform
    Padding.transform = _idempotent_pad_transform(original)
    try:
        yield
    finally:
        Padding.transform = original


def _converter():
    """The ``tflite2onnx`` module, or a one-line :class:`ModelError` saying how to install it."""
    try:
        import tflite2onnx
    except ImportError:
        raise ModelError(
            "converting the pose model needs tflite2onnx: pip install 'capture2notation[models]' "
            "(or set C2N_POSE_MODEL to an ONNX model you already have)"
        ) from None
    return tflite2onnx


def convert_tflite(tflite_path, onnx_path) -> Path:
    """Convert a TFLite model to ONNX with tflite2onnx plus the shared-Pad fix."""
    tflite2onnx = _converter()

    onnx_path = Path(onnx_path)
    # tflite2onnx logs a warning per float16 weight it folds and per empty
    # bias; they are expected for this model and would drown the output.
    t2o_log = logging.getLogger("tflite2onnx")
    level = t2o_log.level
    t2o_log.setLevel(logging.ERROR)
    try:
        with patched_tflite2onnx():
            tflite2onnx.convert(str(tflite_path), str(onnx_path))
    except ModelError:
        raise
    except Exception as exc:  # the converter raises bare AssertionError/IndexError
        raise ModelError(f"tflite2onnx could not convert {tflite_path}: {type(exc).__name__}: {exc}") from exc
    finally:
        t2o_log.setLevel(level)
    _canonicalise(onnx_path)
    return onnx_path


def _canonicalise(onnx_path: Path) -> None:
    """Sort initializers and value infos by name, in place.

    tflite2onnx collects them in Python sets, so their order (and the file's
    sha256) changes from run to run; sorted, every conversion of the same
    TFLite file gives the same bytes, and concurrent fetches agree.
    """
    import onnx

    model = onnx.load(str(onnx_path))
    for field in (model.graph.initializer, model.graph.value_info):
        items = sorted(field, key=lambda x: x.name)
        del field[:]
        field.extend(items)
    onnx.save(model, str(onnx_path))


def verify_onnx(path) -> None:
    """Check an ONNX file is the BlazePose landmark model and runs.

    Checks the input and output shapes against :data:`INPUT_SHAPE` and
    :data:`OUTPUT_SHAPES`, runs one mid-grey frame and requires finite outputs
    and a pose-flag probability in [0, 1].

    Raises
    ------
    ModelError
        With the file and the first mismatch.
    """
    import onnxruntime as ort

    try:
        sess = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    except Exception as exc:  # onnxruntime raises its own untyped errors
        raise ModelError(f"{path}: onnxruntime cannot load the model: {exc}") from exc
    inputs = sess.get_inputs()
    if len(inputs) != 1 or tuple(inputs[0].shape) != INPUT_SHAPE:
        raise ModelError(f"{path}: input {[(i.name, i.shape) for i in inputs]}, expected one input {INPUT_SHAPE}")
    shapes = tuple(tuple(o.shape) for o in sess.get_outputs())
    if shapes != OUTPUT_SHAPES:
        raise ModelError(f"{path}: outputs {shapes}, expected {OUTPUT_SHAPES}")
    outs = sess.run(None, {inputs[0].name: np.full(INPUT_SHAPE, 0.5, np.float32)})
    if not all(np.isfinite(o).all() for o in outs):
        raise ModelError(f"{path}: non-finite outputs on a grey frame")
    flag = float(outs[1].ravel()[0])
    if not 0.0 <= flag <= 1.0:
        raise ModelError(f"{path}: pose flag {flag} on a grey frame, expected a probability in [0, 1]")
