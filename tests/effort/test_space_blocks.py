"""The pooled Space regression's per-movement elimination against a dense design."""

import numpy as np

from capture2notation.effort.fit import _RHO_GRID, _ar1_regression


def _dense(tau, x, y, w):
    """Reference: the dense AR(1) regression (one column per movement's line term), column 0 reported."""
    n, p = x.shape
    step = np.diff(tau, prepend=-np.inf)
    first = step <= 0
    first[0] = True
    delta = np.median(step[~first])
    expo = np.where(first, 0.0, step / delta)
    rho = _RHO_GRID[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        phi = np.exp(expo[None, :] * np.log(np.abs(rho)))
    phi = np.where(first[None, :], 0.0, np.where((rho < 0) & (np.round(expo) % 2 == 1), -phi, phi))
    c = 1.0 / np.sqrt(1.0 - phi * phi)
    sw = np.sqrt(w)
    xw, yw = x * sw[:, None], y * sw
    xt = c[:, :, None] * (xw[None] - phi[:, :, None] * np.roll(xw, 1, axis=0)[None])
    yt = c * (yw[None] - phi * np.roll(yw, 1)[None])
    gram = np.einsum("kni,knj->kij", xt, xt)
    coef = np.linalg.solve(gram, np.einsum("kni,kn->ki", xt, yt)[..., None])[..., 0]
    rss = np.sum((yt - np.einsum("kni,ki->kn", xt, coef)) ** 2, axis=1)
    dof = n - p
    logp = -0.5 * np.linalg.slogdet(gram)[1] - 0.5 * dof * np.log(rss) - 0.5 * np.sum(np.log(1.0 - phi * phi), axis=1)
    post = np.exp(logp - logp.max())
    post /= post.sum()
    mk = coef[:, 0]
    vk = rss / dof * np.linalg.inv(gram)[:, 0, 0] * dof / (dof - 2.0)
    mean = post @ mk
    return mean, np.sqrt(post @ (vk + (mk - mean) ** 2))


def test_block_elimination_matches_the_dense_design():
    rng = np.random.default_rng(7)
    taus, groups = [], []
    for g in range(6):
        n = int(rng.integers(12, 40))
        taus.append(np.sort(rng.uniform(0.01, 0.99, n)))
        groups.append(np.full(n, g))
    tau, grp = np.concatenate(taus), np.concatenate(groups)
    bump = np.sin(np.pi * tau)
    y = -0.03 * bump + 0.01 * grp * tau + 0.002 * np.cumsum(rng.standard_normal(tau.size)) / 5
    w = rng.uniform(0.3, 1.0, tau.size)
    onehot = (grp[:, None] == np.arange(6)[None, :]).astype(float)
    x = np.column_stack([bump, onehot, onehot * tau[:, None]])
    ref_mean, ref_sd = _dense(tau, x, y, w)
    mean, sd = _ar1_regression(tau, bump, y, w, grp)
    assert abs(mean - ref_mean) < 1e-9 and abs(sd - ref_sd) < 1e-9 * max(ref_sd, 1.0)
    # one movement: the line is shared
    one = slice(0, taus[0].size)
    ref = _dense(tau[one], np.column_stack([bump[one], np.ones(taus[0].size), tau[one]]), y[one], w[one])
    got = _ar1_regression(tau[one], bump[one], y[one], w[one])
    assert np.allclose(got, ref, rtol=1e-8, atol=1e-12)
