"""The evaluation report: verdicts from the metrics, like-with-like comparisons, expanded labels,
the how-to-read block, per-robot thresholds, videos."""

import json
import re

import pytest

from agents.pipeline.cli import evaluate_main
from agents.pipeline.episode import EpisodeRecord
from agents.pipeline.evaluation import EnvResult, PolicyRun, SuiteResult
from agents.pipeline.report import benchmark_section, verdict_lines, verdict_paragraph
from agents.pipeline.summary import aggregate

AGENT_ENVS = ["HexapodStewartTilt-v1", "HexapodIrregularTerrain-v1"]  # with a shipped knobs agent
ENVS = [*AGENT_ENVS, "HexapodDitchCrossing-v0"]


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    out = tmp_path_factory.mktemp("report") / "rep"
    argv = ["--envs", *ENVS, "--policies", "analytical", "zero", "ppo:models/{env_id}/knobs"]
    argv += ["--episodes", "2", "--max-episode-steps", "40", "--output-dir", str(out)]
    argv += ["--set", "missing_models=skip"]
    assert evaluate_main([*argv, "--no-progress"]) == 0
    return out


def test_report_has_no_placeholder_a_verdict_per_env_and_the_reading_guide(report):
    md = (report / "report.md").read_text()
    page = (report / "report.html").read_text()
    for text in (md, page):
        # the policy name as given may hold {env_id} (the note on the env without the model)
        text = text.replace("models/{env_id}/knobs", "")
        assert not re.search(r"\{[a-z_]+\}", text), "unexpanded placeholder"
        assert "How to read this report" in text
    for env_id in ENVS:
        section = md.split(f"## {env_id}\n", 1)[1].split("\n## ", 1)[0]
        assert section.count("**Verdict:**") == 1
        if env_id in AGENT_ENVS:
            assert "| knobs |" in section  # the short alias of ppo:models/{env_id}/knobs
            assert f"models/{env_id}/knobs" in section  # its source names the path
            assert "vs the reference motion (`zero`)" in section
        assert "\n| zero |" in section  # the reference-motion row
    assert "static margin > 0 mm" in md
    metrics = json.loads((report / "metrics.json").read_text())
    assert metrics["envs"]["HexapodStewartTilt-v1"]["xi_deg"] == 20.0
    assert metrics["envs"]["HexapodDitchCrossing-v0"]["xi_deg"] == 0.0
    # each env's episode-end and success bounds, as its settings set them
    rules = metrics["envs"]["HexapodStewartTilt-v1"]["rules"]
    assert rules["success_max_tilt_deg"] == 2.5 and rules["success_max_tipping_share"] is None
    assert "| HexapodStewartTilt-v1 | FASM >= ξ_f = 20 deg" in md
    assert "| 20 | tilt > 10° | <= 2.5° | - |" in md


def _record(length, time_below, distance, tipped, dt=0.02, fasm_min=None):
    return EpisodeRecord(
        length=length,
        duration_s=length * dt,
        episode_return=float(length),
        reward_terms={},
        success=not tipped,
        tipped_over=tipped,
        terminated=tipped,
        truncated=not tipped,
        fasm_min_deg=fasm_min if fasm_min is not None else (5.0 if tipped else 30.0),
        fasm_mean_deg=30.0,
        time_below_xi_s=time_below,
        fraction_below_xi=time_below / (length * dt),
        distance_m=distance,
        energy_j=None,
    )


def test_a_policy_that_tips_early_does_not_beat_on_shorter_totals():
    """Early tip-over: less total time below ξ (0.1 vs 0.5 s) only because the episode is 0.2 s
    long; per second it is worse (50 % vs 25 % of the time), and so is its speed."""
    result = EnvResult("Env-v0", {}, 100, 0.02, [])
    result.runs = {
        "zero": PolicyRun("zero", "zero", [_record(100, 0.5, 1.0, False)] * 3),
        "ppo:x": PolicyRun("ppo:x", "x", [_record(10, 0.1, 0.05, True)] * 3),
    }
    aggs = {n: aggregate(r.episodes) for n, r in result.runs.items()}
    lines, verdicts = verdict_lines(result, aggs)
    (bullet,) = lines
    assert "tips over more often" in bullet
    better = bullet.split("Better on", 1)[1] if "Better on" in bullet else ""
    assert "time below" not in better and "distance" not in better
    outcome = {v.metric: v.outcome for v in verdicts}
    assert outcome["fraction_below_xi"] == "worse" and outcome["speed_m_s"] == "worse"
    assert "time_below_xi_s" not in outcome and "distance_m" not in outcome
    paragraph = verdict_paragraph(result, aggs)
    assert paragraph.startswith("**Verdict:** `zero` succeeds most often (3/3 successes")


def test_the_verdict_compares_the_leaders_stability_only_where_it_differs():
    result = EnvResult("Env-v0", {}, 100, 0.02, [])
    upright = [_record(100, 0.5, 1.0, False)] * 3  # minimum FASM 30°
    result.runs = {name: PolicyRun(name, name, upright) for name in ("analytical", "ppo:x")}
    aggs = {n: aggregate(r.episodes) for n, r in result.runs.items()}
    paragraph = verdict_paragraph(result, aggs)
    assert "Their median minimum FASM is the same, 30°." in paragraph
    assert "differs" not in paragraph
    nearly = [_record(100, 0.5, 1.0, False, fasm_min=30.0 - 1e-6)] * 3  # prints the same
    result.runs["ppo:x"] = PolicyRun("ppo:x", "x", nearly)
    aggs = {n: aggregate(r.episodes) for n, r in result.runs.items()}
    assert "differs" not in verdict_paragraph(result, aggs)
    lower = [_record(100, 0.5, 1.0, False, fasm_min=20.0)] * 3
    result.runs["ppo:x"] = PolicyRun("ppo:x", "x", lower)
    aggs = {n: aggregate(r.episodes) for n, r in result.runs.items()}
    assert "differs: median minimum FASM 30° for `analytical` down to 20° for `ppo:x`" in (
        verdict_paragraph(result, aggs)
    )


def test_video_is_written_linked_and_embedded(tmp_path):
    pytest.importorskip("imageio_ffmpeg")
    out = tmp_path / "rep"
    argv = ["--envs", "HexapodIrregularTerrain-v0", "--policies", "zero", "--episodes", "1"]
    argv += ["--max-episode-steps", "20", "--output-dir", str(out), "--no-progress", "--video"]
    assert evaluate_main(argv) == 0
    videos = sorted((out / "videos").glob("*.mp4"))
    assert [v.name for v in videos] == ["HexapodIrregularTerrain-v0_zero.mp4"]
    assert videos[0].stat().st_size > 1000
    assert "(videos/HexapodIrregularTerrain-v0_zero.mp4)" in (out / "report.md").read_text()
    assert (
        '<video controls muted loop width="480" src="videos/' in (out / "report.html").read_text()
    )


def test_envs_option_keeps_the_suite_kwargs(tmp_path):
    out = tmp_path / "rep"
    argv = ["--config", "configs/evaluate_v0_shipped.yaml", "--envs", "HexapodIrregularTerrain-v0"]
    argv += ["--policies", "zero", "--episodes", "1"]
    argv += ["--max-episode-steps", "5", "--output-dir", str(out), "--no-progress"]
    assert evaluate_main(argv) == 0
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["envs"]["HexapodIrregularTerrain-v0"]["kwargs"] == {
        "task_distribution": "test",
        "gait_ground_search": "always",
    }


def test_sampled_tasks_are_broken_down_and_run_dirs_give_learning_curves(tmp_path):
    from helpers.cliff_ppo_runs import TINY, train

    assert train(tmp_path, "tiny", overrides=TINY) == 0
    out = tmp_path / "rep"
    envs = json.dumps([{"id": "HexapodCliffWalk-v0", "kwargs": {"task_distribution": "test"}}])
    argv = ["--set", f"envs={envs}", "--policies", "zero", f"ppo:{tmp_path / 'tiny'}"]
    argv += ["--episodes", "4", "--max-episode-steps", "30", "--output-dir", str(out)]
    assert evaluate_main([*argv, "--no-progress"]) == 0
    md = (out / "report.md").read_text()
    assert "By sampled task parameter" in md and "| cliff_x | ≤ " in md
    assert "figures/HexapodCliffWalk-v0_learning.png" in md
    episodes = json.loads((out / "metrics.json").read_text())["envs"]["HexapodCliffWalk-v0"]
    tasks = [e["task"]["cliff_x"] for e in episodes["policies"]["zero"]["episodes"]]
    assert len(set(tasks)) == 4 and all(3.4 <= x <= 4.0 for x in tasks)


def test_named_references_are_compared_in_order_and_each_pair_once():
    """A suite's `references` add like-for-like comparisons (here learned gains against the
    paper's gains in the same action mode); labelled names ({env_id} expanded) are found."""
    result = EnvResult("Env-v0", {}, 100, 0.02, [])
    ok, tipped = _record(100, 0.5, 1.0, False), _record(10, 0.1, 0.05, True)
    result.runs = {
        "analytical": PolicyRun("analytical", "a", [ok] * 3),
        "ppo:m/{env_id}/paper": PolicyRun("ppo:m/{env_id}/paper", "p", [ok, ok, tipped]),
        "ppo:m/{env_id}/learned": PolicyRun("ppo:m/{env_id}/learned", "l", [ok] * 3),
    }
    aggs = {result.label(n): aggregate(r.episodes) for n, r in result.runs.items()}
    lines, _ = verdict_lines(result, aggs, ("analytical", "ppo:m/{env_id}/paper"))
    assert [line.split(": success", 1)[0] for line in lines] == [
        "- `ppo:m/Env-v0/paper` vs the analytical controller (`analytical`)",
        "- `ppo:m/Env-v0/learned` vs the analytical controller (`analytical`)",
        "- `ppo:m/Env-v0/learned` vs `ppo:m/Env-v0/paper`",
    ]
    assert "success 3/3 vs 2/3" in lines[2]
    default, _ = verdict_lines(result, aggs)  # analytical and zero; zero did not run
    assert len(default) == 2


def test_references_must_be_among_the_policies(tmp_path, capsys):
    argv = ["--envs", "HexapodCliffWalk-v0", "--policies", "analytical", "zero"]
    argv += ["--episodes", "1", "--output-dir", str(tmp_path / "rep"), "--no-progress"]
    assert evaluate_main([*argv, "--set", "references=[random]"]) == 2
    assert "references ['random'] are not among the policies ['analytical', 'zero']" in (
        capsys.readouterr().err
    )
    assert not (tmp_path / "rep").exists()


def test_success_and_tip_over_differences_say_when_they_are_not_resolved():
    """3 of 20 tasks apart is within what the draw of 20 tasks could make: the bullet and the
    verdict say so; 20 of 20 apart is resolved, and the verdict says that too."""
    ok, tipped = _record(100, 0.0, 1.0, False), _record(10, 0.1, 0.05, True)
    result = EnvResult("Env-v0", {}, 100, 0.02, [])
    result.runs = {
        "zero": PolicyRun("zero", "zero", [ok] * 17 + [tipped] * 3),
        "ppo:x": PolicyRun("ppo:x", "x", [ok] * 20),
    }
    aggs = {n: aggregate(r.episodes) for n, r in result.runs.items()}
    (bullet,), _ = verdict_lines(result, aggs)
    assert "success 20/20 vs 17/20 (not resolved: difference [0, 0.3" in bullet
    assert "tip-overs 0/20 vs 3/20 (not resolved: difference [-0.3" in bullet
    assert "lead in successes over `zero` is not resolved" in verdict_paragraph(result, aggs)
    result.runs["zero"] = PolicyRun("zero", "zero", [tipped] * 20)
    aggs = {n: aggregate(r.episodes) for n, r in result.runs.items()}
    (bullet,), _ = verdict_lines(result, aggs)
    assert "success 20/20 vs 0/20," in bullet and "tip-overs 0/20 vs 20/20." in bullet
    assert "lead in successes over `zero` is resolved" in verdict_paragraph(result, aggs)


def test_the_report_says_which_checkpoint_it_evaluated(report, tmp_path):
    """A shipped model's sources name its checkpoint and steps; a best/ kept from step 0 says it
    is the initial policy."""
    from agents.run_files.artifacts import checkpoint_note, read_meta

    md = (report / "report.md").read_text()
    for env_id in AGENT_ENVS:
        meta = read_meta(f"models/{env_id}/knobs")
        note = checkpoint_note(f"models/{env_id}/knobs")
        assert note.startswith(f" ({meta['kind']} checkpoint at {meta['num_timesteps']} ")
        assert note in md
    (tmp_path / "meta.json").write_text(json.dumps({"kind": "best", "num_timesteps": 0}))
    note = checkpoint_note(tmp_path)
    assert note == " (best checkpoint at 0 env steps: the initial policy, no training step kept)"
    # learner steps in the run's own unit (its config.yaml)
    assert "at 3072 tipping events)" in checkpoint_note("models/HexapodStewartTilt-v1/knobs")
    assert "at 640 episodes)" in checkpoint_note("models/HexapodIrregularTerrain-v1/knobs")


def test_speed_gets_no_verdict_where_the_robot_stands(report):
    """The Stewart tilt's robot stands: its distance is drift or a fall, so no policy is
    better for a larger one; the ditch's robot walks, and speed is compared there."""
    metrics = json.loads((report / "metrics.json").read_text())["envs"]
    stewart = metrics["HexapodStewartTilt-v1"]
    assert stewart["unranked_metrics"] == ["speed_m_s"]
    assert not [c for c in stewart["comparisons"] if c["metric"] == "speed_m_s"]
    ditch = metrics["HexapodDitchCrossing-v0"]
    assert [c for c in ditch["comparisons"] if c["metric"] == "speed_m_s"]


def test_an_unstable_episode_is_flagged_and_its_repeated_readings_count_once():
    from agents.pipeline.episode import EpisodeAccumulator
    from hexapod_envs import info_keys as keys

    acc = EpisodeAccumulator(dt=0.1, xi_f_deg=20.0)
    good = {keys.FASM_MARGIN_DEG: 10.0, "actuator_power_w": 5.0, keys.IS_SUCCESS: False}
    acc.add(1.0, good)
    acc.add(0.0, {**good, keys.SIM_UNSTABLE: True})  # the env repeats the last good readings
    record = acc.finish(terminated=False, truncated=True)
    assert record.sim_unstable and record.scalar_metrics()["sim_unstable"]
    assert record.length == 2 and record.energy_j == pytest.approx(0.5)
    assert record.time_below_xi_s == pytest.approx(0.1) and record.fraction_below_xi == 1.0
    stable = EpisodeAccumulator(dt=0.1, xi_f_deg=20.0)
    stable.add(1.0, good)
    assert not stable.finish(terminated=False, truncated=True).sim_unstable


def test_a_study_row_names_the_checkpoint_it_evaluates(tmp_path):
    """A trial's row gives the steps of the model evaluated (best/ first), not of its newest
    checkpoint: a best/ kept from step 0 is the initial policy however long the trial ran."""
    from agents.pipeline.eval_config import EvaluationSuite
    from agents.pipeline.study import expand_studies
    from agents.run_files.artifacts import checkpoint_note
    from agents.run_files.configtools import from_mapping

    sweep = tmp_path / "sweep"
    trial = sweep / "trial_00000"
    (sweep / "sweep.yaml").parent.mkdir()
    (sweep / "sweep.yaml").write_text("{}\n")
    for sub, steps in (("best", 0), ("final", 100352)):
        (trial / sub).mkdir(parents=True)
        (trial / sub / "model.zip").write_bytes(b"")
        meta = {"kind": sub, "num_timesteps": steps}
        (trial / sub / "meta.json").write_text(json.dumps(meta))
    (trial / "config.yaml").write_text("{}\n")
    (trial / "trial.json").write_text(json.dumps({"overrides": ["train.seed=0"]}))
    suite = from_mapping(
        EvaluationSuite, {"envs": ["HexapodCliffWalk-v0"], "policies": [f"ppo:{sweep}"]}
    )
    _, (study,), _ = expand_studies(suite)
    (label,) = study.members.values()
    assert label == "train.seed=0" + checkpoint_note(trial / "best")
    assert "at 0 env steps: the initial policy" in label


def test_a_difference_without_a_paired_interval_says_so():
    """One episode per policy gives no interval: the verdict must not read as resolved."""
    result = EnvResult("Env-v0", {}, 100, 0.02, [])
    result.runs = {
        "zero": PolicyRun("zero", "zero", [_record(100, 0.5, 1.0, False)]),
        "ppo:x": PolicyRun("ppo:x", "x", [_record(100, 0.1, 2.0, False)]),
    }
    aggs = {n: aggregate(r.episodes) for n, r in result.runs.items()}
    (bullet,), verdicts = verdict_lines(result, aggs)
    assert all(v.interval is None for v in verdicts if v.outcome != "tie")
    assert "distance per second 1 vs 0.5 (no paired interval)" in bullet


def test_benchmark_scores_run_from_random_to_the_analytical_controller(tmp_path):
    """With analytical and random on an env, the report scores every policy on that scale (the
    IQM across envs beside it) and plots success against the task difficulty."""
    out = tmp_path / "bench"
    argv = ["--config", "configs/evaluate_default.yaml", "--envs", "HexapodStewartTilt-v1"]
    argv += ["--episodes", "3", "--output-dir", str(out), "--no-progress"]
    assert evaluate_main(argv) == 0
    md = (out / "report.md").read_text()
    section = md.split("## Benchmark scores\n", 1)[1].split("\n## ", 1)[0]
    assert "| policy | HexapodStewartTilt-v1 | IQM [95 % CI] |" in section
    assert "| `analytical` | 100 | 100 [100, 100] |" in section
    assert "| `random` | 0 | 0 [0, 0] |" in section
    assert (out / "figures" / "success_by_difficulty.png").is_file()
    metrics = json.loads((out / "metrics.json").read_text())
    episode = metrics["envs"]["HexapodStewartTilt-v1"]["policies"]["analytical"]["episodes"][0]
    assert "difficulty" in json.dumps(episode)


def test_a_policy_run_on_some_envs_gets_its_scores_there_and_no_iqm():
    """A learned agent shipped for one of two envs: its row shows its score there, "-" on the
    other env and no IQM, and the text says why."""
    ok, tipped = _record(100, 0.0, 1.0, False), _record(100, 0.0, 1.0, True)
    envs = []
    for env_id, agent in (("A-v1", True), ("B-v1", False)):
        result = EnvResult(env_id, {}, 100, 0.02, [])
        result.runs = {
            "analytical": PolicyRun("analytical", "a", [ok, ok, ok, tipped]),
            "random": PolicyRun("random", "r", [tipped] * 4),
        }
        if agent:
            result.runs["ppo:x"] = PolicyRun("ppo:x", "x", [ok, ok, tipped, tipped])
        envs.append(result)
    table, text = benchmark_section(SuiteResult(None, envs, [], 0.0))
    rows = {row[0]: row[1:] for row in table.rows}
    assert rows["`ppo:x`"] == ["67", "-", "n/a"]  # 2/4 against 3/4 above 0/4
    assert rows["`analytical`"][:2] == ["100", "100"] and rows["`analytical`"][2] != "n/a"
    assert "without a score on every env (-)" in text


def test_envs_left_out_of_the_scores_are_said_why():
    """An env where random actions match the controller and one where no reference ran are left
    out for different reasons."""
    ok, tipped = _record(100, 0.0, 1.0, False), _record(100, 0.0, 1.0, True)
    runs = {
        "A-v1": {"analytical": [ok, tipped], "random": [tipped, tipped]},
        "B-v1": {"analytical": [tipped, tipped], "random": [tipped, tipped]},
        "C-v1": {"zero": [ok, ok]},
    }
    envs = []
    for env_id, by_policy in runs.items():
        result = EnvResult(env_id, {}, 100, 0.02, [])
        result.runs = {n: PolicyRun(n, n, episodes) for n, episodes in by_policy.items()}
        envs.append(result)
    _, text = benchmark_section(SuiteResult(None, envs, [], 0.0))
    assert "(the analytical controller does not beat random actions there): `B-v1`." in text
    assert "(`analytical` or `random` did not run there): `C-v1`." in text


def test_an_env_whose_episodes_all_ran_one_task_says_so():
    """A -v0 id evaluated on its default (the paper's scenario): the seeds change only the reset
    noise, which the setup text says; sampled tasks get no such sentence."""
    from dataclasses import replace

    from agents.pipeline.report import _env_setup_text

    paper = {"cliff_x": 2.8, "difficulty": 0.47}
    result = EnvResult("HexapodCliffWalk-v0", {}, 100, 0.02, [])
    same = [replace(_record(100, 0.0, 1.0, False), task=dict(paper)) for _ in range(3)]
    result.runs = {"zero": PolicyRun("zero", "z", same)}
    assert "Every episode ran the same task" in _env_setup_text(result)
    other = replace(same[0], task={**paper, "cliff_x": 3.1})
    result.runs = {"zero": PolicyRun("zero", "z", [*same[:2], other])}
    assert "Every episode ran the same task" not in _env_setup_text(result)


def test_the_rules_cells_name_each_bound_and_dash_the_missing_ones():
    from agents.pipeline.report import _rule_cells

    cliff = {
        "tip_over_angle_deg": 15.0,
        "tip_over_margin_time": 1.0,
        "success_max_tilt_deg": 8.0,
        "success_max_tipping_share": 0.1,
    }
    assert _rule_cells(cliff) == [
        "tilt > 15°, or FASM <= 0 for 1 s",
        "<= 8°",
        "<= 10 % of the episode",
    ]
    v0 = dict.fromkeys(cliff) | {"tip_over_angle_deg": 20.0}
    assert _rule_cells(v0) == ["tilt > 20°", "-", "-"]
    assert _rule_cells({}) == ["-", "-", "-"]  # an env without the settings


def test_ppo_policies_get_short_unambiguous_aliases():
    from agents.pipeline.evaluation import policy_aliases

    names = ["analytical", "ppo:models/{env_id}/ppo", "ppo:models/{env_id}/hybrid"]
    names += ["ppo:runs/a/best", "ppo:runs/b/best", "ppo:runs/gains/final", "ppo:other/gains"]
    aliases = policy_aliases(names)
    assert aliases["ppo:models/{env_id}/ppo"] == "ppo"
    assert aliases["ppo:models/{env_id}/hybrid"] == "hybrid"
    assert aliases["ppo:runs/a/best"] == "a" and aliases["ppo:runs/b/best"] == "b"
    # two policies would both be "gains": each keeps its full name
    assert "ppo:runs/gains/final" not in aliases and "ppo:other/gains" not in aliases
    assert "analytical" not in aliases
    assert policy_aliases(["ppo:models/x/analytical", "analytical"]) == {}
    # a template component is no name of its own; what is left of one is expanded per env
    from agents.pipeline.evaluation import EnvResult

    names = ["ppo:mine/{env_id}", "ppo:runs/{env_id}_seed0/best"]
    result = EnvResult("HexapodCliffWalk-v1", {}, None, None, [], aliases=policy_aliases(names))
    assert [result.label(n) for n in names] == ["mine", "HexapodCliffWalk-v1_seed0"]
