#!/usr/bin/env python3
"""Coefficients of the polynomial atan used by the air-field kernel (models/fast_atan2.h).

atan(u) = u * P(z), z = u^2, for |u| <= tan(pi/8) (after range reduction). P is the Chebyshev
interpolant of atan(u)/u on z in [0, tan(pi/8)^2], re-expressed as a polynomial in
s = (z - c) / h, s in [-1, 1] (well conditioned), evaluated by Horner. Pure Python, exact rational
conversion from the Chebyshev basis. Prints C++ and the max error measured on a dense grid.
"""
import math
from fractions import Fraction

DEG = 9
ZMAX = math.tan(math.pi / 8) ** 2
C, H = ZMAX / 2, ZMAX / 2


def f(z):
    if z == 0:
        return 1.0
    u = math.sqrt(z)
    return math.atan(u) / u


# Chebyshev coefficients from the values at the Chebyshev nodes (first kind).
n = DEG + 1
nodes = [math.cos(math.pi * (k + 0.5) / n) for k in range(n)]
vals = [f(C + H * s) for s in nodes]
cheb = []
for j in range(n):
    acc = sum(vals[k] * math.cos(math.pi * j * (k + 0.5) / n) for k in range(n))
    cheb.append(acc * (2.0 / n) * (0.5 if j == 0 else 1.0))

# T_j(s) as exact integer polynomials, then the monomial coefficients in s.
T = [[Fraction(1)], [Fraction(0), Fraction(1)]]
for j in range(2, n):
    prev, prev2 = T[j - 1], T[j - 2]
    nxt = [Fraction(0)] + [2 * c for c in prev]
    for i, c in enumerate(prev2):
        nxt[i] -= c
    T.append(nxt)
mono = [Fraction(0)] * n
for j in range(n):
    for i, c in enumerate(T[j]):
        mono[i] += Fraction(cheb[j]) * c
coef = [float(c) for c in mono]


def poly_atan(u):
    z = u * u
    s = (z - C) / H
    p = 0.0
    for c in reversed(coef):
        p = p * s + c
    return u * p


worst = 0.0
N = 200000
t8 = math.tan(math.pi / 8)
for i in range(N + 1):
    u = -t8 + 2 * t8 * i / N
    worst = max(worst, abs(poly_atan(u) - math.atan(u)))
print(f"// degree {DEG} in s; max |error| on |u| <= tan(pi/8): {worst:.3g} rad")
print(f"constexpr double kZCenter = {C!r};")
print(f"constexpr double kZHalfWidth = {H!r};")
print("constexpr double kAtanPoly[] = {  // s^0 ... s^%d" % DEG)
for c in coef:
    print(f"    {c!r},")
print("};")
