from agents.pipeline.cli import default_headless_gl

default_headless_gl()  # MUJOCO_GL=egl where libEGL exists, before MuJoCo loads
