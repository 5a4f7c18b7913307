"""quadcosim.spaces.Box: gymnasium.spaces.Box's contract, a small version (no dependency on gymnasium)."""

from typing import Any, Optional, Sequence, Tuple

import numpy as np

__all__ = ["Box"]


class Box:
    """A box in R^shape: every entry between low and high (gymnasium.spaces.Box's contract, a small version).

    low, high: numbers or arrays (broadcast to shape; -inf/inf for unbounded); shape: taken from them
    when None; dtype: of the samples and of the bounds. sample() draws with the space's numpy
    Generator (np_random; seed() reseeds it): uniform where both bounds are finite, a normal draw where
    neither is, an exponential one beyond a single finite bound.
    """

    def __init__(self, low: Any, high: Any, shape: Optional[Sequence[int]] = None, dtype: Any = np.float32,
                 seed: Optional[int] = None):
        self.dtype = np.dtype(dtype)
        if shape is None:
            shape = np.broadcast(np.asarray(low), np.asarray(high)).shape
        self.shape: Tuple[int, ...] = tuple(int(s) for s in shape)
        self.low = np.broadcast_to(np.asarray(low, dtype=self.dtype), self.shape).copy()
        self.high = np.broadcast_to(np.asarray(high, dtype=self.dtype), self.shape).copy()
        if np.any(self.low > self.high) or np.any(np.isnan(self.low)) or np.any(np.isnan(self.high)):
            raise ValueError("Box: low must not exceed high (and neither be NaN)")
        self._np_random: Optional[np.random.Generator] = None
        if seed is not None:
            self.seed(seed)

    @property
    def np_random(self) -> np.random.Generator:
        if self._np_random is None:
            self._np_random = np.random.default_rng()
        return self._np_random

    def seed(self, seed: Optional[int] = None) -> list:
        """Reseeds the space's Generator (None: fresh entropy)."""
        self._np_random = np.random.default_rng(seed)
        return [seed]

    def is_bounded(self, manner: str = "both") -> bool:
        below, above = bool(np.all(np.isfinite(self.low))), bool(np.all(np.isfinite(self.high)))
        return {"both": below and above, "below": below, "above": above}[manner]

    def sample(self) -> np.ndarray:
        rng = self.np_random
        low, high = self.low.astype(np.float64), self.high.astype(np.float64)
        out = np.empty(self.shape, dtype=np.float64)
        fl, fh = np.isfinite(low), np.isfinite(high)
        both, none_, lo_only, hi_only = fl & fh, ~fl & ~fh, fl & ~fh, ~fl & fh
        out[both] = rng.uniform(low[both], high[both])
        out[none_] = rng.normal(size=int(none_.sum()))
        out[lo_only] = low[lo_only] + rng.exponential(size=int(lo_only.sum()))
        out[hi_only] = high[hi_only] - rng.exponential(size=int(hi_only.sum()))
        if np.issubdtype(self.dtype, np.integer):
            out = np.floor(out)
        return np.clip(out.astype(self.dtype), self.low, self.high)

    def contains(self, x: Any) -> bool:
        """x has the space's shape, a dtype that casts to its dtype, and every entry within the bounds."""
        if not isinstance(x, np.ndarray):
            try:
                x = np.asarray(x, dtype=self.dtype)
            except (ValueError, TypeError):
                return False
        if x.shape != self.shape or not np.can_cast(x.dtype, self.dtype):
            return False
        return bool(np.all(x >= self.low) and np.all(x <= self.high))

    def __contains__(self, x: Any) -> bool:
        return self.contains(x)

    def __eq__(self, other: Any) -> bool:
        return (isinstance(other, Box) and self.shape == other.shape and self.dtype == other.dtype
                and np.array_equal(self.low, other.low) and np.array_equal(self.high, other.high))

    def __repr__(self) -> str:
        return f"Box({self.low.min()}, {self.high.max()}, {self.shape}, {self.dtype})"
