"""Training and evaluation pipeline: typed YAML configs, vec-env building, SB3 PPO training with
TensorBoard logging and checkpoints, an evaluation runner for any set of policies, and a report
writer (Markdown, self-contained HTML, JSON).

Generic over Gymnasium env ids: nothing here imports `hexapod_envs`; env packages are imported by
name from the configs (``env.gym_packages``) so that their ids are registered. `train.py` and
`evaluate.py` at the repository root are thin front ends over `agents.pipeline.cli`.
"""
