"""Bad keywords and values raise ValueError with the command line's message; a bad spec file
names its file and line; the interpreter goes on."""
import subprocess

import pytest

import portalsim


def cli_error(portalsim_bin, *args):
    """The message `portalsim` prints for args (after "portalsim: error: ")."""
    r = subprocess.run([portalsim_bin, *args], capture_output=True, text=True)
    assert r.returncode != 0
    line = r.stderr.strip().splitlines()[-1]
    assert line.startswith("portalsim: error: "), r.stderr
    return line[len("portalsim: error: "):]


@pytest.mark.parametrize("keywords, flags", [
    (dict(rotate="abc"), ["--rotate", "abc"]),
    (dict(what="pictures"), ["--what", "pictures"]),
    (dict(seed=-3), ["--seed", "-3"]),
    (dict(count=0), ["--count", "0"]),
    (dict(model="optical"), ["--model", "optical"]),
    (dict(objects="5..2"), ["--objects", "5..2"]),
    (dict(rule="gun&&"), ["--rule", "gun&&"]),
    (dict(pool=["gun", "bazooka"]), ["--pool", "gun,bazooka"]),
])
def test_generator_value_errors_are_the_command_lines(keywords, flags, portalsim_bin, tmp_path):
    want = cli_error(portalsim_bin, "generate", *flags, "--out", str(tmp_path / "x"))
    with pytest.raises(ValueError) as e:
        portalsim.Generator(**keywords)
    assert str(e.value) == want
    assert next(iter(keywords)) in str(e.value)  # it names the keyword


def test_unknown_keyword_is_named():
    with pytest.raises(ValueError, match=r"^rotation: not a keyword of portalsim.Generator"):
        portalsim.Generator(rotation=30)
    with pytest.raises(ValueError, match=r"^out: not a keyword"):
        portalsim.Generator(out="somewhere")
    with pytest.raises(ValueError, match=r"^--balance: expected True or False"):
        portalsim.Generator(balance="yes")


def test_help_is_not_a_keyword():
    """help=True once raised CLI11's "This should be caught in your main function" (issue 36)."""
    for make in (lambda: portalsim.Generator(seed=1, help=True), lambda: portalsim.simulate(["gun"], help=True)):
        with pytest.raises(ValueError) as e:
            make()
        message = str(e.value)
        assert message.startswith("help: not a keyword of portalsim."), message
        assert "the keywords are" in message and "help" not in message.split("the keywords are ")[1].split(", ")


@pytest.mark.parametrize("key, value", [("png_level", 3), ("image_format", "jpg"), ("compress", True)])
def test_flags_for_files_only_are_refused(key, value):
    """Generator writes no files: a knob of generate's files is refused, saying so (issue 36)."""
    flag = key.replace("_", "-")
    with pytest.raises(ValueError) as e:
        portalsim.Generator(seed=1, what="images", **{key: value})
    assert str(e.value).startswith(f"{key}: not a keyword of portalsim.Generator (--{flag} only shapes the files "
                                   "`portalsim generate` writes, and portalsim.Generator writes none)"), str(e.value)


def test_per_scenario_bodies_are_not_for_simulate(portalsim_bin, tmp_path):
    """simulate shows one chosen subject; a body per scenario is a data set's (generate, the stream)."""
    want = cli_error(portalsim_bin, "simulate", "gun", "--bodies", "per-scenario", "--out", str(tmp_path / "x"))
    with pytest.raises(ValueError) as e:
        portalsim.simulate(["gun"], bodies="per-scenario")
    assert str(e.value) == want and "per-scenario bodies are drawn per scenario of a data set" in want


def test_bad_spec_file_names_file_and_line(tmp_path, portalsim_bin):
    spec = tmp_path / "bad.toml"
    spec.write_text('seed = 1\nrule = "gun"\nrotate = "sideways"\n')
    want = cli_error(portalsim_bin, "generate", "--spec", str(spec), "--out", str(tmp_path / "x"))
    with pytest.raises(ValueError) as e:
        portalsim.Generator(spec=spec)
    assert str(e.value) == want
    assert f"{spec}:3" in str(e.value) and "rotate" in str(e.value)
    with pytest.raises(ValueError, match="nowhere.toml"):
        portalsim.Generator(spec=tmp_path / "nowhere.toml")


def test_simulate_errors_are_the_command_lines(portalsim_bin, tmp_path):
    want = cli_error(portalsim_bin, "simulate", "none", "bazooka", "--out", str(tmp_path / "x"))
    with pytest.raises(ValueError) as e:
        portalsim.simulate(["none", "bazooka"])
    assert str(e.value) == want
    with pytest.raises(ValueError, match=r"^--fov: expected|^fov: not a keyword"):
        portalsim.simulate(["gun"], fov=3)


def test_bad_batches_and_the_interpreter_goes_on():
    gen = portalsim.Generator(seed=1)
    for start, count in ((0, 0), (0, 1 << 25)):
        with pytest.raises(ValueError, match="count"):
            gen.batch(start, count)
    with pytest.raises(TypeError):
        gen.batch(-1, 4)
    assert gen.batch(0, 4)["metal"].shape == (4, 19)  # still works


@pytest.mark.parametrize("datasets, message", [
    (["uper"], '"uper" is not a dataset (the datasets are upper, lower, ir, ir_index, '),
    (["upper", "upper"], '"upper" is named twice'),
    ([], "name at least one dataset"),
    (["mask_upper"], '"mask_upper" is not a dataset'),  # masks need annotations=True
])
def test_bad_datasets_name_the_dataset(datasets, message):
    with pytest.raises(ValueError) as e:
        portalsim.Generator(seed=1, what="images", datasets=datasets)
    assert str(e.value).startswith("datasets: ") and message in str(e.value), str(e.value)


def test_a_name_that_is_no_dataset_is_told_first():
    """With what="features", "upper" is a dataset these keywords do not make, "nope" no dataset
    at all: the typo is the one named (issue 36)."""
    with pytest.raises(ValueError) as e:
        portalsim.Generator(seed=1, datasets=("upper", "nope"))
    assert str(e.value).startswith('datasets: "nope" is not a dataset (the datasets are '), str(e.value)
    with pytest.raises(ValueError) as e:
        portalsim.Generator(seed=1, datasets=("upper",))
    assert str(e.value).startswith('datasets: "upper" is not a dataset of these keywords (they make '), str(e.value)
    assert 'what="images"' in str(e.value)
