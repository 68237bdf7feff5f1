"""Issue item 1: a log is untrusted input; ``cosim replay`` reads its input files only from the log itself.

Each crafted log comes from a real one (``_craft.rewrite``): its embedded
scenario or SUMO config names a local file (a stand-in for a private key) by
an absolute path or a ``..`` path, or an attachment has an unsafe name. The
replay must refuse with one line naming the key or file, write nothing, and
the "secret" must appear in no file it leaves behind.
"""
from __future__ import annotations

import json
from pathlib import Path

import pytest
from _craft import rewrite
from _robust import assert_one_line, cosim_cli

from cosim.log import open_log

SECRET = b"-----BEGIN OPENSSH PRIVATE KEY----- not really\n"


def no_secret_anywhere(folder: Path) -> None:
    for path in folder.rglob("*"):
        if path.is_file() and path.name != "id_rsa":
            assert SECRET not in path.read_bytes(), path


@pytest.fixture
def secret(tmp_path: Path) -> Path:
    path = tmp_path / "home" / ".ssh" / "id_rsa"
    path.parent.mkdir(parents=True)
    path.write_bytes(SECRET)
    return path


def _scenario_text(log: Path) -> str:
    return open_log(log).attachments["scenario.toml"].decode()


def test_a_road_profile_outside_the_log_is_refused(profiled_log: Path, tmp_path: Path, secret: Path) -> None:
    text = _scenario_text(profiled_log)
    for name in (str(secret), "../home/.ssh/id_rsa", "data/../../home/.ssh/id_rsa"):
        crafted = rewrite(profiled_log, tmp_path / "crafted.mcap", attachments={
            "scenario.toml": text.replace('profile = "data/road.csv"', f'profile = "{name}"').encode()},
            metadata={"cosim": {"inputs": json.dumps({})}})
        result = cosim_cli("replay", str(crafted), "--out", str(tmp_path / "new.mcap"), "--quiet", cwd=tmp_path)
        assert_one_line(result, 2, "road.profile", "not one of the log's attachments")
        assert not (tmp_path / "new.mcap").exists() and not (tmp_path / "runs").exists()
    no_secret_anywhere(tmp_path)


def test_a_road_profile_that_is_a_local_text_file_is_not_echoed(profiled_log: Path, tmp_path: Path) -> None:
    passwd = tmp_path / "passwd"
    passwd.write_text("root:x:0:0:root:/root:/bin/bash\nsecret-second-line:x:1:1\n")
    text = _scenario_text(profiled_log)
    scenario = text.replace('profile = "data/road.csv"', f'profile = "{passwd}"').encode()
    crafted = rewrite(profiled_log, tmp_path / "crafted.mcap", attachments={"scenario.toml": scenario},
                      metadata={"cosim": {"inputs": "{}"}})
    result = cosim_cli("replay", str(crafted), "--quiet", cwd=tmp_path)
    line = assert_one_line(result, 2, "road.profile")
    assert "secret-second-line" not in result.stderr + result.stdout and str(passwd) in line
    # With the log's inputs record intact, the key is pointed back at the log's own attachment.
    crafted = rewrite(profiled_log, tmp_path / "crafted.mcap", attachments={"scenario.toml": scenario})
    result = cosim_cli("replay", str(crafted), "--out", str(tmp_path / "own.mcap"), "--quiet", cwd=tmp_path)
    assert result.returncode == 0 and "identical, bit for bit" in result.stdout, result.stderr
    assert b"secret-second-line" not in (tmp_path / "own.mcap").read_bytes()


@pytest.mark.parametrize("option", ["net-file", "route-files", "additional-files"])
def test_files_named_by_the_embedded_sumo_config_must_be_attachments(sumo_log: Path, tmp_path: Path, secret: Path,
                                                                     option: str) -> None:
    config = open_log(sumo_log).attachments["sumo/light.sumocfg"].decode()
    if option == "additional-files":
        config = config.replace("</input>", f'<additional-files value="{secret}"/></input>')
    elif option == "net-file":
        config = config.replace('value="bridge.net.xml"', f'value="{secret}"')
    else:
        config = config.replace('value="vtypes.add.xml,light.rou.xml"', 'value="vtypes.add.xml,../../home/.ssh/id_rsa"')
    assert config != open_log(sumo_log).attachments["sumo/light.sumocfg"].decode()
    crafted = rewrite(sumo_log, tmp_path / "crafted.mcap", attachments={"sumo/light.sumocfg": config.encode()})
    result = cosim_cli("replay", str(crafted), "--out", str(tmp_path / "new.mcap"), "--quiet", cwd=tmp_path)
    assert_one_line(result, 2, option, "not one of the log's attachments")
    assert not (tmp_path / "new.mcap").exists()
    no_secret_anywhere(tmp_path)


@pytest.mark.parametrize("name", ["/tmp/evil.csv", "../evil.csv", "sumo/../../evil.csv", "a\\..\\evil.csv", ""])
def test_an_attachment_with_an_unsafe_name_is_refused(profiled_log: Path, tmp_path: Path, name: str) -> None:
    crafted = rewrite(profiled_log, tmp_path / "crafted.mcap", attachments={name: b"x,r\n0,0\n"})
    result = cosim_cli("replay", str(crafted), "--quiet", cwd=tmp_path)
    assert_one_line(result, 2, "unsafe name")
    assert not (tmp_path.parent / "evil.csv").exists() and not Path("/tmp/evil.csv").exists()


def test_an_input_the_log_does_not_hold_is_refused(profiled_log: Path, tmp_path: Path) -> None:
    crafted = rewrite(profiled_log, tmp_path / "crafted.mcap", attachments={"data/road.csv": None})
    result = cosim_cli("replay", str(crafted), "--quiet", cwd=tmp_path)
    assert_one_line(result, 2, "data/road.csv", "missing")
    crafted = rewrite(profiled_log, tmp_path / "crafted.mcap",
                      metadata={"cosim": {"inputs": json.dumps({"bridge.section": "data/road.csv"})}})
    assert_one_line(cosim_cli("replay", str(crafted), "--quiet", cwd=tmp_path), 2, "unknown key")


def test_the_genuine_logs_still_replay_bit_for_bit(profiled_log: Path, sumo_log: Path, tmp_path: Path) -> None:
    for log in (profiled_log, sumo_log):
        result = cosim_cli("replay", str(log), "--out", str(tmp_path / f"{log.parent.name}.mcap"), "--quiet",
                           cwd=tmp_path)
        assert result.returncode == 0, result.stderr
        assert "identical, bit for bit" in result.stdout
