"""The success ensemble in a form for answering queries: all members in a few batched matrix products.

:class:`primitives.training.success.SuccessNet` keeps its members as separate modules, which is what training and the
shipped files want (one optimiser per member's parameters, ``members.K.*`` keys). Answering a query that way runs
every layer once per member: 25 small matrix products for five members, each paying torch's per-call overhead on a
cloud of a few hundred points. :class:`StackedEnsemble` holds the same weights stacked:

- the members' first point layers side by side, one ``(9, M * width)`` product for all members (they read the
  same scaled points, or with the contact encoder the same contact-frame points, ``(13, M * width)``);
- the other layers as ``(M, in, out)`` stacks, one batched product (``baddbmm``) per layer for all members.

It computes what :meth:`SuccessNet.forward` computes (the same sums, grouped differently: the answers agree to
float32 rounding, about 1e-7), in a third of the time on two cores (``affordplan bench query``). It is a snapshot:
weights changed in the net after it is built are not seen. No gradients flow through it.
"""

from __future__ import annotations

import torch

from affordplan.errors import InputError


class StackedEnsemble:
    """P(success) from a :class:`~primitives.training.success.SuccessNet`'s weights, stacked across its members.

    Args:
        net: the ensemble to snapshot (any number of members, any ``n_decision``).
    """

    def __init__(self, net) -> None:
        members = list(net.members)
        first = members[0].points[0]
        self.n_members = len(members)
        self.width = first.weight.shape[0]
        self.n_decision = net.n_decision
        self.member_input = net.member_input  # what the members read, from (obs, decision)
        with torch.no_grad():
            # First point layer, all members at once: x (B*N, 9) @ (9, M*width).
            self.w_in = torch.cat([m.points[0].weight for m in members]).t().contiguous()
            self.b_in = torch.cat([m.points[0].bias for m in members]).clone()
            # Second point layer and the three head layers as (M, in, out) stacks with (M, 1, out) biases.
            self.layers = [(torch.stack([layer(m).weight.t() for m in members]).contiguous(),
                            torch.stack([layer(m).bias for m in members])[:, None, :].clone())
                           for layer in (lambda m: m.points[2], lambda m: m.head[0], lambda m: m.head[2],
                                         lambda m: m.head[4])]
            self.platt = net.platt.clone()

    @torch.no_grad()
    def __call__(self, obs: torch.Tensor, decision: torch.Tensor) -> torch.Tensor:
        """Calibrated probability of success ``(B,)`` from observations ``(B, N, 9)`` (goal frame, metres) and
        decision features ``(B, >= n_decision)`` (:func:`primitives.training.success.decision_features`)."""
        logit = self.member_logits(obs, decision).mean(dim=0)  # the members' mean logit, as SuccessNet.logit
        return torch.sigmoid(self.platt[0] * logit + self.platt[1])

    @torch.no_grad()
    def member_probabilities(self, obs: torch.Tensor, decision: torch.Tensor) -> torch.Tensor:
        """Each member's probability of success ``(M, B)``, through the ensemble's Platt scaling: where the members
        disagree, the data they were fitted on did not settle the answer (a deep ensemble's uncertainty)."""
        return torch.sigmoid(self.platt[0] * self.member_logits(obs, decision) + self.platt[1])

    @torch.no_grad()
    def member_logits(self, obs: torch.Tensor, decision: torch.Tensor) -> torch.Tensor:
        """Each member's logit ``(M, B)`` (arguments as :meth:`__call__`)."""
        if obs.ndim != 3 or decision.ndim != 2 or decision.shape[0] != obs.shape[0] \
                or decision.shape[1] < self.n_decision:
            raise InputError(f"expected observations (B, N, 9) and decision features (B, >= {self.n_decision}), "
                             f"got {tuple(obs.shape)} and {tuple(decision.shape)}")
        b, n, _ = obs.shape
        m, w = self.n_members, self.width
        x = self.member_input(obs, decision).reshape(b * n, -1)
        h = torch.addmm(self.b_in, x, self.w_in).relu_().view(b * n, m, w).transpose(0, 1)  # (M, B*N, w)
        (w_pts, b_pts), *head = self.layers
        h = torch.baddbmm(b_pts, h, w_pts).relu_().view(m, b, n, -1)  # (M, B, N, 2w)
        z = torch.cat([h.amax(dim=2), h.mean(dim=2), decision[:, :self.n_decision].expand(m, b, -1)], dim=2)
        for k, (weight, bias) in enumerate(head):
            z = torch.baddbmm(bias, z, weight)
            if k < len(head) - 1:
                z = z.relu_()
        return z.squeeze(-1)
