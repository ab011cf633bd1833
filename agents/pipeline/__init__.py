"""Training and evaluation pipeline: vec-env building, SB3 PPO training with TensorBoard logging
and checkpoints, an evaluation runner for any set of policies, a report writer (Markdown,
self-contained HTML, JSON), sweeps and the command-line front ends. The top layer: nothing below
imports it. What a run leaves on disk (its typed config, model directories, safely loaded model
files, recorded env settings) is one layer below, in `agents.run_files`, so that a policy can
load a trained model (`agents.ppo`) without the pipeline.

Generic over Gymnasium env ids: nothing here imports `hexapod_envs`; env packages are imported by
name from the configs (``env.gym_packages``) so that their ids are registered. `train.py` and
`evaluate.py` at the repository root are thin front ends over `agents.pipeline.cli`.
"""
