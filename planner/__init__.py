"""Planning over resting states and SE(2) poses (resting-state graph, OMPL, closed-loop execution)."""
