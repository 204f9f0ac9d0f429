"""Model fetch / convert / verify / cache, and the tflite2onnx shared-Pad fix."""

from __future__ import annotations

import json
import subprocess
import types
import zipfile

import numpy as np
import pytest
import tflite2onnx
from tflite2onnx.layout import Layout
from tflite2onnx.op.padding import Padding

from capture2notation.errors import ModelError
from capture2notation.keypoints import model as pm


def _pad_op(pads_tensor, layout):
    """A stand-in for a tflite2onnx Pad operator: what Padding.transform reads."""
    data_in = types.SimpleNamespace(layout=layout)
    return types.SimpleNamespace(inputs=[data_in, pads_tensor])


def _shared_pads():
    # TFLite NHWC paddings: (begin, end) per axis, H padded (1, 2), W padded (3, 4).
    data = np.array([[0, 0], [1, 2], [3, 4], [0, 0]], dtype=np.int64)
    return types.SimpleNamespace(name="shared/paddings", data=data.copy(), shape=[4, 2])


NCHW_PADS = [0, 0, 1, 3, 0, 0, 2, 4]  # ONNX: begins (N, C, H, W) then ends


def test_unpatched_transform_fails_on_shared_pads():
    """The bug: the second Pad sees the already-flattened constant."""
    pads = _shared_pads()
    a, b = _pad_op(pads, Layout("NHWC", "NCHW")), _pad_op(pads, Layout("NHWC", "NCHW"))
    Padding.transform(a)
    assert list(pads.data) == NCHW_PADS
    with pytest.raises(IndexError):
        Padding.transform(b)


def test_patched_transform_is_idempotent_for_shared_pads():
    pads = _shared_pads()
    a, b = _pad_op(pads, Layout("NHWC", "NCHW")), _pad_op(pads, Layout("NHWC", "NCHW"))
    with pm.patched_tflite2onnx():
        Padding.transform(a)
        Padding.transform(b)
        Padding.transform(a)
    assert list(pads.data) == NCHW_PADS
    assert list(pads.shape) == [8]
    # The patch is undone on exit.
    assert not hasattr(Padding.transform, "__wrapped__")


def test_patched_transform_refuses_conflicting_layouts():
    pads = _shared_pads()
    a, b = _pad_op(pads, Layout("NHWC", "NCHW")), _pad_op(pads, None)
    with pm.patched_tflite2onnx():
        Padding.transform(a)
        with pytest.raises(ModelError, match="shared/paddings"):
            Padding.transform(b)


def test_resolve_model_prefers_explicit_path_then_env(tmp_path, monkeypatch):
    explicit, env = tmp_path / "a.onnx", tmp_path / "b.onnx"
    explicit.write_bytes(b"x")
    env.write_bytes(b"y")
    monkeypatch.setenv(pm.ENV_MODEL, str(env))
    assert pm.resolve_model(explicit) == explicit
    assert pm.resolve_model() == env
    monkeypatch.setenv(pm.ENV_MODEL, str(tmp_path / "missing.onnx"))
    with pytest.raises(ModelError, match=r"missing\.onnx.*C2N_POSE_MODEL"):
        pm.resolve_model()


def test_no_model_and_no_fetch_says_what_to_run(tmp_path, monkeypatch):
    monkeypatch.delenv(pm.ENV_MODEL, raising=False)
    monkeypatch.setenv(pm.ENV_CACHE, str(tmp_path))
    with pytest.raises(ModelError) as err:
        pm.resolve_model(fetch=False)
    msg = str(err.value)
    assert "c2n models fetch" in msg and "C2N_POSE_MODEL" in msg and "--model" in msg


def test_failed_download_says_what_to_run(tmp_path, monkeypatch):
    """No network: pip fails; the error names the fix, not a traceback."""

    def fake_run(cmd, **kwargs):
        assert "--no-deps" in cmd and f"mediapipe=={pm.MEDIAPIPE_VERSION}" in cmd
        return subprocess.CompletedProcess(cmd, 1, "", "ERROR: Could not find a version (network unreachable)")

    monkeypatch.setattr(pm.subprocess, "run", fake_run)
    with pytest.raises(ModelError, match=r"network unreachable.*c2n models fetch"):
        pm.fetch_model(cache=tmp_path)
    assert not (tmp_path / pm.ONNX_NAME).exists()


def test_wheel_with_wrong_model_is_rejected(tmp_path):
    wheel = tmp_path / f"mediapipe-{pm.MEDIAPIPE_VERSION}-fake.whl"
    with zipfile.ZipFile(wheel, "w") as zf:
        zf.writestr(pm.TFLITE_MEMBER, b"not the model")
    with pytest.raises(ModelError, match="sha256"):
        pm.fetch_model(cache=tmp_path / "cache", wheel=wheel)
    empty = tmp_path / "empty.whl"
    with zipfile.ZipFile(empty, "w") as zf:
        zf.writestr("other.txt", b"")
    with pytest.raises(ModelError, match="cannot read"):
        pm.fetch_model(cache=tmp_path / "cache", wheel=empty)


def test_verify_rejects_a_different_model(tmp_path):
    import onnx
    from onnx import TensorProto, helper

    node = helper.make_node("Identity", ["x"], ["y"])
    graph = helper.make_graph(
        [node], "g", [helper.make_tensor_value_info("x", TensorProto.FLOAT, [1, 3, 8, 8])],
        [helper.make_tensor_value_info("y", TensorProto.FLOAT, [1, 3, 8, 8])],
    )  # fmt: skip
    path = tmp_path / "other.onnx"
    onnx.save(helper.make_model(graph, opset_imports=[helper.make_opsetid("", 13)], ir_version=8), path)
    with pytest.raises(ModelError, match="expected one input"):
        pm.verify_onnx(path)


@pytest.mark.model
def test_cached_model_matches_manifest(pose_model_path):
    pm.verify_onnx(pose_model_path)
    manifest_path = pose_model_path.parent / pm.MANIFEST_NAME
    if not manifest_path.exists():
        pytest.skip("model given by C2N_POSE_MODEL, not from the cache")
    manifest = json.loads(manifest_path.read_text())
    assert manifest["tflite_sha256"] == pm.TFLITE_SHA256
    assert manifest["onnx_sha256"] == pm.sha256_file(pose_model_path)


@pytest.mark.model
def test_conversion_needs_the_fix_and_reproduces_the_cache(pose_model_path, tmp_path):
    tflite = pm.cached_tflite_path(pose_model_path.parent)
    if not tflite.exists():
        pytest.skip("no cached TFLite source next to the model")
    with pytest.raises(IndexError):  # unpatched tflite2onnx 0.4.1
        import logging

        logging.getLogger("tflite2onnx").setLevel(logging.ERROR)
        tflite2onnx.convert(str(tflite), str(tmp_path / "raw.onnx"))
    out = pm.convert_tflite(tflite, tmp_path / "fixed.onnx")
    pm.verify_onnx(out)
    # Conversions are byte-for-byte reproducible (concurrent fetches agree).
    again = pm.convert_tflite(tflite, tmp_path / "again.onnx")
    assert pm.sha256_file(again) == pm.sha256_file(out)
    import onnxruntime as ort

    x = np.random.default_rng(0).random(pm.INPUT_SHAPE, dtype=np.float32)
    ref = ort.InferenceSession(str(pose_model_path), providers=["CPUExecutionProvider"]).run(None, {"input_1": x})
    new = ort.InferenceSession(str(out), providers=["CPUExecutionProvider"]).run(None, {"input_1": x})
    for r, n in zip(ref, new):
        np.testing.assert_allclose(n, r, rtol=0, atol=1e-5)


def test_session_rejects_a_model_that_is_not_blazepose(tmp_path):
    import onnx
    from onnx import TensorProto, helper

    from capture2notation.keypoints.blazepose import make_session

    graph = helper.make_graph(
        [helper.make_node("Identity", ["x"], ["y"])], "g",
        [helper.make_tensor_value_info("x", TensorProto.FLOAT, [1, 3, 256, 256])],
        [helper.make_tensor_value_info("y", TensorProto.FLOAT, [1, 3, 256, 256])],
    )  # fmt: skip
    path = tmp_path / "other.onnx"
    onnx.save(helper.make_model(graph, opset_imports=[helper.make_opsetid("", 13)], ir_version=8), path)
    with pytest.raises(ModelError, match=r"other\.onnx: not the BlazePose"):
        make_session(path)
    (tmp_path / "junk.onnx").write_bytes(b"junk")
    with pytest.raises(ModelError, match=r"junk\.onnx"):
        make_session(tmp_path / "junk.onnx")


def test_first_use_fetches_automatically_and_caches(tmp_path, monkeypatch, caplog):
    """An empty cache triggers one fetch (with a message); a valid cache is reused."""
    monkeypatch.delenv(pm.ENV_MODEL, raising=False)
    monkeypatch.setenv(pm.ENV_CACHE, str(tmp_path))
    calls = []

    def fake_fetch(cache=None, **kw):
        calls.append(cache)
        model = pm.cached_model_path(cache)
        model.write_bytes(b"model bytes")
        manifest = {"onnx_sha256": pm.sha256_file(model)}
        (cache / pm.MANIFEST_NAME).write_text(json.dumps(manifest))
        return model

    monkeypatch.setattr(pm, "fetch_model", fake_fetch)
    with caplog.at_level("WARNING", logger=pm.__name__):
        first = pm.resolve_model()
    assert calls == [tmp_path] and "fetching mediapipe==0.10.14" in caplog.text
    assert pm.resolve_model() == first and len(calls) == 1  # cached now
    first.write_bytes(b"tampered")  # hash no longer matches the manifest
    pm.resolve_model()
    assert len(calls) == 2
