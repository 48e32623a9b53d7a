"""The asset resolver and the name constants agree with the XML."""

import mujoco
import pytest

from visuomotor_gym import assets
from visuomotor_gym.body import names

OBJ = {
    "body": mujoco.mjtObj.mjOBJ_BODY,
    "joint": mujoco.mjtObj.mjOBJ_JOINT,
    "actuator": mujoco.mjtObj.mjOBJ_ACTUATOR,
    "geom": mujoco.mjtObj.mjOBJ_GEOM,
    "site": mujoco.mjtObj.mjOBJ_SITE,
    "camera": mujoco.mjtObj.mjOBJ_CAMERA,
    "equality": mujoco.mjtObj.mjOBJ_EQUALITY,
}


@pytest.fixture(scope="module")
def model():
    return mujoco.MjModel.from_xml_path(str(assets.asset_path("catch.xml")))


@pytest.mark.parametrize("kind", sorted(names.ALL_NAMES))
def test_every_constant_names_an_element(model, kind):
    missing = [n for n in names.ALL_NAMES[kind] if mujoco.mj_name2id(model, OBJ[kind], n) < 0]
    assert not missing, f"{kind} names missing from catch.xml: {missing}"


def test_every_body_joint_geom_site_camera_actuator_is_named(model):
    unnamed = []
    for kind, count in (("joint", model.njnt), ("actuator", model.nu), ("site", model.nsite),
                        ("camera", model.ncam), ("body", model.nbody)):
        for i in range(1 if kind == "body" else 0, count):  # body 0 is the world
            if not mujoco.mj_id2name(model, OBJ[kind], i):
                unnamed.append((kind, i))
    for i in range(model.ngeom):
        if not mujoco.mj_id2name(model, OBJ["geom"], i):
            unnamed.append(("geom", i))
    assert not unnamed, f"unnamed elements: {unnamed}"


def test_body_joints_are_contiguous_and_first(model):
    """The env relies on the 10 torso+arm joints taking qpos/dof/actuator indices 0..9."""
    for i, n in enumerate(names.BODY_JOINTS):
        j = mujoco.mj_name2id(model, OBJ["joint"], n)
        assert model.jnt_qposadr[j] == i and model.jnt_dofadr[j] == i
        assert mujoco.mj_name2id(model, OBJ["actuator"], n) == i


def test_eye_ranges_match_eom_2019(model):
    az = model.joint(names.EYE_AZIMUTH).range
    el = model.joint(names.EYE_ELEVATION).range
    assert az == pytest.approx([-0.7714, 0.7714], abs=1e-3)  # +-44.2 deg
    assert el == pytest.approx([-0.8221, 0.4835], abs=1e-3)  # -47.1 .. 27.7 deg


def test_env_var_override_and_missing_asset(tmp_path, monkeypatch):
    monkeypatch.setenv(assets.ASSETS_ENV_VAR, str(tmp_path))
    assert assets.assets_dir() == tmp_path
    with pytest.raises(FileNotFoundError, match="no asset named"):
        assets.asset_path("catch.xml")
    monkeypatch.setenv(assets.ASSETS_ENV_VAR, str(tmp_path / "nope"))
    with pytest.raises(FileNotFoundError, match="not a directory"):
        assets.assets_dir()


def test_compiled_catch_models_are_unchanged_by_the_shared_head_eye_fragment():
    """The head+eye subtree moved into ``common/head_eye.xml`` (shared by every body): the compiled
    catch models must be byte-identical to the ones compiled before the move (MJB sha256, recorded
    per MuJoCo version because the binary format may change between releases)."""
    import hashlib
    import json
    import tempfile
    from pathlib import Path

    import mujoco

    from visuomotor_gym.assets import asset_path

    recorded = json.loads((Path(__file__).parent / "golden" / "compiled_models.json").read_text())
    if mujoco.__version__ not in recorded:
        pytest.skip(f"no compiled-model digest recorded for MuJoCo {mujoco.__version__}")
    for scene, digest in recorded[mujoco.__version__].items():
        model = mujoco.MjModel.from_xml_path(str(asset_path(scene)))
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "model.mjb"
            mujoco.mj_saveModel(model, str(path), None)
            assert hashlib.sha256(path.read_bytes()).hexdigest() == digest, scene
    assert "common/head_eye.xml" in asset_path("common/upper_body.xml").read_text()
