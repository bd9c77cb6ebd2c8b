"""A small stereo transformer in the manner of STTR (Li et al., ICCV 2021), written from the
paper's description, sized to train from scratch on a CPU.

A shared CNN turns each image into a feature map at 1/4 resolution. Transformer layers then let
every feature attend along its image row: to its own row (self-attention, with a learned bias
per relative offset) and to the same row of the other image (cross-attention). The last
cross-attention's scores between left and right features, with a learned "dustbin" for left
features that have no match (occlusions), are balanced by a few Sinkhorn iterations (entropic
optimal transport: each right feature is matched about once). Disparity is regressed around the
best match (the probability-weighted position in a 3-wide window), so there is no disparity
range to fix in advance and negative disparities (off-axis rigs) need nothing special. A small
context network on the left image refines the upsampled disparity and occlusion.

Disparity follows ``ambfplus.stereo``: d = x_left - x_right in pixels of the input images.
"""

from __future__ import annotations

import math

import torch
import torch.nn.functional as F
from torch import nn

DOWNSAMPLE = 4  #: input pixels per feature


class ResidualBlock(nn.Module):
    def __init__(self, channels: int, dilation: int = 1) -> None:
        super().__init__()
        self.conv1 = nn.Conv2d(channels, channels, 3, padding=dilation, dilation=dilation)
        self.conv2 = nn.Conv2d(channels, channels, 3, padding=dilation, dilation=dilation)
        self.norm1 = nn.GroupNorm(8, channels)
        self.norm2 = nn.GroupNorm(8, channels)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        y = F.relu(self.norm1(self.conv1(x)))
        return F.relu(x + self.norm2(self.conv2(y)))


class FeatureExtractor(nn.Module):
    """Image -> features at 1/4 resolution, with context from a 1/8 branch."""

    def __init__(self, channels: int) -> None:
        super().__init__()
        half = max(8, channels // 8 * 4)  # half resolution is costly: fewer channels there
        self.stem = nn.Sequential(
            nn.Conv2d(3, half, 5, stride=2, padding=2), nn.GroupNorm(8, half), nn.ReLU(),
            ResidualBlock(half),
            nn.Conv2d(half, channels, 3, stride=2, padding=1), nn.GroupNorm(8, channels),
            nn.ReLU(), ResidualBlock(channels),
        )  # fmt: skip
        self.coarse = nn.Sequential(
            nn.Conv2d(channels, channels, 3, stride=2, padding=1), nn.GroupNorm(8, channels),
            nn.ReLU(), ResidualBlock(channels, dilation=2),
        )  # fmt: skip
        self.merge = nn.Conv2d(2 * channels, channels, 1)

    def forward(self, image: torch.Tensor) -> torch.Tensor:
        fine = self.stem(image)
        coarse = F.interpolate(
            self.coarse(fine), size=fine.shape[-2:], mode="bilinear", align_corners=False
        )
        return self.merge(torch.cat([fine, coarse], dim=1))


class RowAttention(nn.Module):
    """Multi-head attention between two sets of rows (N, W, C), with a learned bias per head
    for each relative column offset (clipped to +-max_offset)."""

    def __init__(self, channels: int, heads: int, max_offset: int) -> None:
        super().__init__()
        self.heads = heads
        self.max_offset = max_offset
        self.query = nn.Linear(channels, channels)
        self.key_value = nn.Linear(channels, 2 * channels)
        self.out = nn.Linear(channels, channels)
        self.offset_bias = nn.Parameter(torch.zeros(heads, 2 * max_offset + 1))

    def forward(self, x: torch.Tensor, source: torch.Tensor) -> torch.Tensor:
        n, width, channels = x.shape
        head_dim = channels // self.heads
        q = self.query(x).view(n, width, self.heads, head_dim).transpose(1, 2)
        k, v = self.key_value(source).view(n, -1, 2, self.heads, head_dim).unbind(2)
        k, v = k.transpose(1, 2), v.transpose(1, 2)
        offsets = (
            torch.arange(source.shape[1], device=x.device)[None, :]
            - torch.arange(width, device=x.device)[:, None]
        )
        bias = self.offset_bias[
            :, offsets.clamp(-self.max_offset, self.max_offset) + self.max_offset
        ]
        attended = F.scaled_dot_product_attention(q, k, v, attn_mask=bias.unsqueeze(0))
        return self.out(attended.transpose(1, 2).reshape(n, width, channels))


class TransformerLayer(nn.Module):
    """Self-attention within each image's rows, then cross-attention to the other image's."""

    def __init__(self, channels: int, heads: int, max_offset: int) -> None:
        super().__init__()
        self.self_attention = RowAttention(channels, heads, max_offset)
        self.cross_attention = RowAttention(channels, heads, max_offset)
        self.feed_forward = nn.Sequential(
            nn.Linear(channels, 2 * channels), nn.GELU(), nn.Linear(2 * channels, channels)
        )
        self.norms = nn.ModuleList(nn.LayerNorm(channels) for _ in range(5))

    def forward(self, left: torch.Tensor, right: torch.Tensor):
        n_self, n_left, n_right, n_ff_l, n_ff_r = self.norms
        left = left + self.self_attention(n_self(left), n_self(left))
        right = right + self.self_attention(n_self(right), n_self(right))
        a, b = n_left(left), n_right(right)
        left, right = left + self.cross_attention(a, b), right + self.cross_attention(b, a)
        left = left + self.feed_forward(n_ff_l(left))
        right = right + self.feed_forward(n_ff_r(right))
        return left, right


def log_optimal_transport(scores: torch.Tensor, dustbin: torch.Tensor, iterations: int):
    """Entropic optimal transport between the rows (left features) and columns (right
    features) of `scores` (N, M, M'), each side extended by a dustbin of score `dustbin`.
    Every real row and column carries one unit of mass, each dustbin absorbs what the other side
    leaves over. Returns log-probabilities (N, M+1, M'+1) whose real rows sum to 1."""
    n, m, k = scores.shape
    column_bin = dustbin.expand(n, m, 1)
    row_bin = dustbin.expand(n, 1, k + 1)
    couplings = torch.cat([torch.cat([scores, column_bin], dim=2), row_bin], dim=1)
    one = scores.new_tensor(1.0)
    log_rows = torch.cat([one.log().expand(m), (one * k).log()[None]])
    log_cols = torch.cat([one.log().expand(k), (one * m).log()[None]])
    u = torch.zeros(n, m + 1, dtype=scores.dtype, device=scores.device)
    v = torch.zeros(n, k + 1, dtype=scores.dtype, device=scores.device)
    for _ in range(iterations):
        u = log_rows - torch.logsumexp(couplings + v[:, None, :], dim=2)
        v = log_cols - torch.logsumexp(couplings + u[:, :, None], dim=1)
    return couplings + u[:, :, None] + v[:, None, :]


class ContextRefinement(nn.Module):
    """Refines upsampled disparity and occlusion with the left image's context."""

    def __init__(self, channels: int = 16, scale: float = 16.0) -> None:
        super().__init__()
        self.scale = scale
        self.net = nn.Sequential(
            nn.Conv2d(5, channels, 3, padding=1), nn.ReLU(),
            ResidualBlock(channels, 1), ResidualBlock(channels, 3),
            nn.Conv2d(channels, 2, 3, padding=1),
        )  # fmt: skip
        nn.init.zeros_(self.net[-1].weight)
        nn.init.zeros_(self.net[-1].bias)

    def forward(self, image, disparity, occlusion):
        x = torch.cat([image, disparity / self.scale, occlusion], dim=1)
        delta, occlusion_logit = self.net(x).unbind(1)
        refined = disparity.squeeze(1) + self.scale * delta
        occlusion_logit = occlusion_logit + torch.logit(occlusion.squeeze(1), eps=1e-4)
        return refined, occlusion_logit


class StereoTransformer(nn.Module):
    """``model(left, right)`` with images (B, 3, H, W) in 0..1 (H and W multiples of 4) returns
    a dict: ``disparity`` (B, H, W) pixels, ``occlusion`` (B, H, W) probability, and what the
    loss needs (``log_assignment``, ``raw_disparity``, ``occlusion_logit``)."""

    def __init__(
        self,
        channels: int = 64,
        layers: int = 4,
        heads: int = 4,
        max_offset: int = 48,
        sinkhorn_iterations: int = 5,
        refine: bool = True,
    ) -> None:
        super().__init__()
        self.features = FeatureExtractor(channels)
        self.layers = nn.ModuleList(
            TransformerLayer(channels, heads, max_offset) for _ in range(layers)
        )
        self.match_norm = nn.LayerNorm(channels)
        self.match_query = nn.Linear(channels, channels)
        self.match_key = nn.Linear(channels, channels)
        self.dustbin = nn.Parameter(torch.tensor(1.0))
        self.sinkhorn_iterations = sinkhorn_iterations
        self.refinement = ContextRefinement() if refine else None
        self.register_buffer("mean", torch.tensor([0.45, 0.42, 0.38]).view(1, 3, 1, 1))

    def forward(self, left: torch.Tensor, right: torch.Tensor) -> dict[str, torch.Tensor]:
        batch, _, height, width = left.shape
        if height % DOWNSAMPLE or width % DOWNSAMPLE:
            raise ValueError(f"image size {width}x{height} is not a multiple of {DOWNSAMPLE}")
        features = self.features(torch.cat([left, right]) - self.mean)
        rows, cols = features.shape[-2:]
        # (B, C, h, w) -> (B h, w, C): every image row is a sequence.
        tokens = features.permute(0, 2, 3, 1).reshape(2 * batch * rows, cols, -1)
        fl, fr = tokens.chunk(2)
        for layer in self.layers:
            fl, fr = layer(fl, fr)
        q = self.match_query(self.match_norm(fl))
        k = self.match_key(self.match_norm(fr))
        scores = q @ k.transpose(1, 2) / math.sqrt(q.shape[-1])
        log_assignment = log_optimal_transport(scores, self.dustbin, self.sinkhorn_iterations)
        raw, occlusion = regress_disparity(log_assignment)
        raw = raw.view(batch, 1, rows, cols)
        occlusion = occlusion.view(batch, 1, rows, cols)
        raw_up = F.interpolate(raw, size=(height, width), mode="bilinear", align_corners=False)
        occ_up = F.interpolate(
            occlusion, size=(height, width), mode="bilinear", align_corners=False
        )
        out = {
            "log_assignment": log_assignment.view(batch, rows, cols + 1, cols + 1),
            "raw_disparity": raw_up.squeeze(1),
        }
        if self.refinement is not None:
            disparity, occlusion_logit = self.refinement(left, raw_up, occ_up.clamp(0, 1))
        else:
            disparity, occlusion_logit = raw_up.squeeze(1), torch.logit(occ_up.squeeze(1), 1e-4)
        out.update(
            disparity=disparity,
            occlusion_logit=occlusion_logit,
            occlusion=torch.sigmoid(occlusion_logit),
        )
        return out


def regress_disparity(log_assignment: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """Disparity (input pixels) and occlusion probability of every left feature from its
    assignment to right features: the probability-weighted column in a 3-wide window around the
    most likely match; occlusion is the probability left outside that window."""
    probability = log_assignment[:, :-1, :-1].exp()  # (N, w, w) real rows and columns
    cols = probability.shape[-1]
    best = probability.argmax(dim=-1, keepdim=True)
    window = (best + torch.arange(-1, 2, device=best.device)).clamp(0, cols - 1)
    weights = probability.gather(-1, window)
    mass = weights.sum(-1)
    match = (weights * window.to(weights.dtype)).sum(-1) / mass.clamp_min(1e-6)
    column = torch.arange(cols, device=match.device, dtype=match.dtype)
    disparity = DOWNSAMPLE * (column - match)
    return disparity, (1.0 - mass).clamp(0.0, 1.0)


def feature_targets(disparity, valid, occlusion, cols: int):
    """Targets at the feature grid: for each feature, the input pixel nearest its centre gives
    the disparity; returns the right column it matches (feature units), and masks for matched
    and occluded features."""
    centre = DOWNSAMPLE // 2  # feature i is centred at input x = 4 i + 2
    d = disparity[:, centre::DOWNSAMPLE, centre::DOWNSAMPLE]
    ok = valid[:, centre::DOWNSAMPLE, centre::DOWNSAMPLE]
    occluded = occlusion[:, centre::DOWNSAMPLE, centre::DOWNSAMPLE] & ok
    x_left = torch.arange(cols, device=d.device, dtype=d.dtype) * DOWNSAMPLE + centre + 0.5
    target = (x_left - d) / DOWNSAMPLE - 0.5
    matched = ok & ~occluded & (target >= 0) & (target <= cols - 1)
    return target, matched, occluded


def stereo_loss(outputs: dict, batch: dict, weights=(1.0, 1.0, 1.0, 0.5)) -> tuple:
    """STTR's losses: relative response (the assignment's probability at the true match,
    interpolated between columns; the dustbin's for occluded features), L1 of the raw and the
    refined disparity on visible pixels, and cross-entropy of the occlusion map on pixels with
    a hit. Returns (total, dict of the terms as floats)."""
    disparity, valid, occlusion = batch["disparity"], batch["valid"], batch["occlusion"]
    log_assignment = outputs["log_assignment"]
    cols = log_assignment.shape[-1] - 1
    target, matched, occluded = feature_targets(disparity, valid, occlusion, cols)
    log_p = log_assignment[..., :-1, :]  # real left features
    lower = target.floor().clamp(0, cols - 1).long()
    upper = (lower + 1).clamp(max=cols - 1)
    t = (target - lower).clamp(0, 1)
    p_lower = log_p.gather(-1, lower.unsqueeze(-1)).squeeze(-1).exp()
    p_upper = log_p.gather(-1, upper.unsqueeze(-1)).squeeze(-1).exp()
    response = -torch.log((1 - t) * p_lower + t * p_upper + 1e-6)
    dustbin = -log_p[..., cols]
    zero = disparity.new_zeros(())
    terms = {
        "response": response[matched].mean() if matched.any() else zero,
        "dustbin": dustbin[occluded].mean() if occluded.any() else zero,
    }
    visible = valid & ~occlusion
    if visible.any():
        terms["raw_l1"] = F.smooth_l1_loss(outputs["raw_disparity"][visible], disparity[visible])
        terms["l1"] = F.smooth_l1_loss(outputs["disparity"][visible], disparity[visible])
    else:
        terms["raw_l1"] = terms["l1"] = zero
    if valid.any():
        terms["occlusion"] = F.binary_cross_entropy_with_logits(
            outputs["occlusion_logit"][valid], occlusion[valid].to(disparity.dtype)
        )
    else:
        terms["occlusion"] = zero
    w_response, w_raw, w_l1, w_occ = weights
    total = (
        w_response * (terms["response"] + terms["dustbin"])
        + w_raw * terms["raw_l1"]
        + w_l1 * terms["l1"]
        + w_occ * terms["occlusion"]
    )
    return total, {name: float(value.detach()) for name, value in terms.items()}
