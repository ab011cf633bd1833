"""What a training run leaves on disk, and how it is read back: below the pipeline, so that a
policy loads a trained model (`agents.ppo`) without importing the pipeline that wrote it.

- `train_config` (with `schedules`): the training config as typed dataclasses, read with the
  typed-YAML tools of `configtools`; a model directory's ``config.yaml`` is one.
- `artifacts`: run directories and self-describing model directories, and `find_model`, which
  resolves a user-given path to a model's files.
- `model_files`: model files that cannot run code when loaded (`load_ppo`, `load_stats`,
  `NormalizationStats`), written atomically.
- `env_settings`: the training env's settings recorded with a model (``env_settings.yaml``).
- `shipped`: where the shipped configs and models are (a checkout or the installed wheel).
- `errors`: `UserError` and `ConfigError`, the errors the front ends print without a traceback.

`agents.pipeline` (training, evaluation, reports, sweeps, the commands) builds on these;
nothing here imports it (tests/project/test_layers.py).
"""
