"""sim: a MuJoCo arm with a two-finger gripper, its action servers, a pick-and-place
task machine and a live viser view.

Modules (each imports mujoco/viser only when used; nothing needs a display):
``world`` (model, seeded episodes, physics thread), ``ik`` (damped least squares),
``servers`` (MoveTo and Gripper action servers), ``task`` (``build_task_machine``),
``scene`` (``start_scene``: the viser view through mjviser), ``demo`` (``SimDemo``,
``run_episodes``: what ``fsmscope demo`` runs).
"""
