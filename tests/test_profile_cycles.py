"""tools/profile_cycles.py finds every part it counts in today's run loops: its anchors occur
once each, and the instrumented copies are valid Python that reads the counter (the script
itself compiles two integrators, minutes: it is run by hand, docs/performance.md)."""

import ast

from tests.paths import ROOT, tool_script


def _script():
    return tool_script("profile_cycles")


def test_the_counters_go_into_todays_run_loops(tmp_path):
    script = _script()
    script.instrumented(ROOT, tmp_path)
    step_files, exact_files = (script.LOOP, script.STEPPER), (script.EXACT_RUN,)
    for files, parts in ((step_files, script.STEP_PARTS), (exact_files, script.EXACT_PARTS)):
        texts = [(tmp_path / f).read_text() for f in files]
        for text in texts:
            ast.parse(text)
            assert "from rbm_cli.base.cycles import cycles" in text
        text = "".join(texts)
        assert text.count("print('CYCLES'") >= 1
        # every part has its counter: prof[i] (the step kernel) or s.cnt[8 + i] (exact)
        for i in range(len(parts)):
            assert (f"prof[{i}] +=" in text) or (f"s.cnt[{8 + i}] +=" in text), (files, i)
    ast.parse((tmp_path / "rbm_cli" / "base" / "cycles.py").read_text())
    # the package copied is untouched but for the three files
    original = (ROOT / "rbm_cli" / "numerics" / "rk.py").read_text()
    assert (tmp_path / "rbm_cli" / "numerics" / "rk.py").read_text() == original


def test_a_changed_run_loop_stops_the_script_in_one_line(tmp_path, monkeypatch):
    script = _script()
    anchors = list(script.ANCHORS)
    f, anchor, replacement = anchors[2]
    anchors[2] = (f, anchor + "# not in the source\n", replacement)
    monkeypatch.setattr(script, "ANCHORS", anchors)
    try:
        script.instrumented(ROOT, tmp_path)
    except SystemExit as exc:
        message = str(exc.code)
        assert message.startswith("profile_cycles: ") and "\n" not in message
    else:
        raise AssertionError("a missing anchor was not refused")


def test_drum_counts_that_are_not_counts_are_refused_in_one_line(monkeypatch):
    script = _script()
    for args in (["--drums"], ["--drums", "0"], ["--drums", "8", "x"], ["--columns", "8"]):
        monkeypatch.setattr(script.sys, "argv", ["profile_cycles.py", *args])
        try:
            script.main()
        except SystemExit as exc:
            message = str(exc.code)
            assert message.startswith("profile_cycles: usage") and "\n" not in message
        else:
            raise AssertionError(f"{args} was not refused")
