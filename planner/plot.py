"""Top-down pictures of plans and executions."""

from __future__ import annotations

import os

import numpy as np

from planner.footprint import footprint, place


def plot_plan(plan, path: str | os.PathLike, execution=None, title: str | None = None) -> None:
    """Obstacles, the workspace, footprints along the planned path, the steps, and (optionally) what happened."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Polygon, Rectangle

    planner, goal = plan.planner, plan.goal
    obj = planner.obj
    ws = planner.workspace
    fig, ax = plt.subplots(figsize=(6, 7))
    ax.add_patch(Rectangle((ws.x[0], ws.y[0]), ws.x[1] - ws.x[0], ws.y[1] - ws.y[0], fill=False, linestyle="--",
                           edgecolor="grey", label="workspace"))
    for i, box in enumerate(planner.obstacles):
        ax.add_patch(Polygon(box.corners_xy(), color="#555555", label="obstacle" if i == 0 else None))
    colours = {"push": "#d98c2b", "spin": "#4c78a8", "roll": "#c0392b"}
    for state, p in plan.paths:
        fp = footprint(obj, state)
        for k in np.linspace(0, len(p) - 1, min(len(p), 12)).astype(int):
            ax.add_patch(Polygon(place(fp, *p[k]), fill=False, edgecolor="#88aa88", linewidth=0.6))
        ax.plot(p[:, 0], p[:, 1], color="#2e8b57", linewidth=1.2)
    for s in plan.steps:
        x0, y0 = s.start_pose[0, 3], s.start_pose[1, 3]
        x1, y1 = s.expected_pose[0, 3], s.expected_pose[1, 3]
        c = colours[s.skill]
        if s.skill == "push":
            ax.annotate("", (x1, y1), (x0, y0), arrowprops=dict(arrowstyle="->", color=c, linewidth=1.5))
        else:
            ax.plot([x0], [y0], marker="o" if s.skill == "spin" else "s", color=c, markersize=6)
    for skill, c in colours.items():
        ax.plot([], [], color=c, marker={"push": ">", "spin": "o", "roll": "s"}[skill], linestyle="", label=skill)
    start_state, *start_xy_yaw = obj.planar_pose(plan.start_pose)
    ax.add_patch(Polygon(place(footprint(obj, start_state), *start_xy_yaw), fill=False,
                         edgecolor="black", linewidth=1.5, label="start"))
    ax.add_patch(plt.Circle(goal.xy, goal.xy_tol, color="#2ca02c", alpha=0.3, label="goal (3 cm)"))
    if execution is not None:
        xy = np.array([[e.pose_before[0, 3], e.pose_before[1, 3]] for e in execution.log]
                      + [[execution.final_pose[0, 3], execution.final_pose[1, 3]]])
        ax.plot(xy[:, 0], xy[:, 1], color="black", linestyle=":", marker=".", label="executed")
        fstate, fx, fy, fyaw = obj.planar_pose(execution.final_pose)
        ax.add_patch(Polygon(place(footprint(obj, fstate), fx, fy, fyaw), fill=False, edgecolor="#2ca02c",
                             linewidth=1.5, label="final"))
    ax.set_xlim(ws.x[0] - 0.05, ws.x[1] + 0.05)
    ax.set_ylim(ws.y[0] - 0.05, ws.y[1] + 0.05)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    status = "" if execution is None else (f"; executed: {'success' if execution.success else 'failed'}, "
                                           f"{execution.n_primitives} primitives, {execution.replans} replans")
    ax.set_title(title or f"{obj.name}: {len(plan.steps)} steps, P={plan.p_success:.2f}{status}", fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def save_frames(frames: list[np.ndarray], path: str | os.PathLike, n: int = 6) -> None:
    """A strip of ``n`` frames (evenly spaced, first and last included) as one PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if not frames:
        return
    idx = np.unique(np.linspace(0, len(frames) - 1, min(n, len(frames))).astype(int))
    fig, axes = plt.subplots(1, len(idx), figsize=(3 * len(idx), 2.4), squeeze=False)
    for ax, i in zip(axes[0], idx):
        ax.imshow(frames[i])
        ax.set_title(f"after {i} primitives" if i else "start", fontsize=8)
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
