"""Tolerances shared by the numpy and the compiled segment kernels (one home for both)."""

#: m^2. Squared length below which a segment counts as a point (its direction is dropped).
EPS = 1e-30
#: Floor of the closest-point denominator, so that parallel lines give a huge ratio that
#: the clamp sends to an end of the segment instead of a division by zero.
TINY = 1e-300
#: Relative size of ``a e - b^2`` (= |d1 x d2|^2) against ``a e`` below which a pair counts
#: as nearly parallel: rounding can then lose its closest points (hypothesis found 6e-5 m
#: off), so its distance is settled by the four end-point-to-segment distances instead.
PARALLEL = 1e-9
