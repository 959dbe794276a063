#!/usr/bin/python3
"""Error propagation Gamma(z) = U_i(z) / U_{i-1}(z) of a chain of sampled followers (doc/math.md,
"Platoons"), with the link's delay, for the paper's laws and the string-stable configuration.

Usage::

    string_stability_analysis.py SCENARIO.yaml --md OUT.md --png OUT.png

SCENARIO is a 1-axis double-integrator scenario with C = I (config/scenarios/platoon_run2.yaml):
its G, L, G_e, S_21 = 0, time headway h, feed-forward gain kappa and time constant tau are used.
The model is the follower's loop at period T with the projection at rest (||xi_hat|| below the
soft bound, as in every run of the report), written independently of the C++ core:

    xi = x_t - x_i,  u = G xi + u_a + u_ff + u_h,  u_a = G_e (xi - xi_hat),  u_h = -k_p h v_i,
    u_ff(k) = a u_ff(k-1) + (1 - a) kappa a_hat(k),  a = exp(-T / tau),  a_hat(k) = u_t(k - D),
    xi_hat+ = e^{F T} xi_hat + (int_0^T e^{F s} ds) (-L xi - B (u_a + u_h) + B (a_hat - u_ff)),
    F = A - B G + L,  x_i+ = e^{A T} x_i + Gamma_T u  (zero-order hold, exact).

Since the target's state is the zero-order-hold response to its own command u_t, every follower
maps u_t to u_i by the same Gamma(z), and so xi_i to xi_{i+1}: |Gamma(e^{jwT})| <= 1 for all w is
l2 string stability; ||g||_1 (g the impulse response) bounds the growth of peaks (l_inf).

Writes OUT.md (sup_w |Gamma|, where, and ||g||_1 per configuration, rate and delay) and OUT.png
(|Gamma| against w). Rerun everything with experiments/string_stability/run.sh.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np
import yaml
from scipy.linalg import expm

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)

A = np.array([[0.0, 1.0], [0.0, 0.0]])
B = np.array([[0.0], [1.0]])
DELAYS = (0.0, "T", 0.02, 0.05, 0.1, 0.15, 0.2, 0.3)   # s ("T": one period)
RATES = (100.0, 1000.0)


def gain(node, key):
    """A 1 x 2 gain from a scenario section: the matrix, or natural_frequency/damping."""
    if "gain" in node:
        return np.array(node["gain"], dtype=float).reshape(1, 2)
    w, z = float(node["natural_frequency"]), float(node["damping"])
    return np.array([[w * w, 2.0 * z * w]])


def read(path):
    with open(path, encoding="utf-8") as fh:
        s = yaml.safe_load(fh)
    m, c = s["model"], s["controller"]
    if m.get("type") != "double_integrator" or int(m.get("dimension", 0)) != 1 or "C" in m:
        raise ValueError(f"{path}: needs a 1-axis double integrator with C = I")
    est = c["estimator"]["gain"]
    L = float(est) * np.eye(2) if np.isscalar(est) else np.array(est, dtype=float)
    info = c.get("leader_information", {}) or {}
    ff = info.get("feedforward", {}) or {}
    return {"G": gain(c["baseline"], "baseline"), "Ge": gain(c["tracker"], "tracker"), "L": L,
            "h": float((c.get("spacing") or {}).get("time_headway", 0.0)),
            "kappa": float(ff.get("gain", 1.0)), "tau": float(ff.get("time_constant", 0.0))}


def zoh(M, N, T):
    """(e^{M T}, int_0^T e^{M s} ds N)."""
    n, m = M.shape[0], N.shape[1]
    E = np.zeros((n + m, n + m))
    E[:n, :n], E[:n, n:] = M * T, N * T
    X = expm(E)
    return X[:n, :n], X[:n, n:]


def loop(p, T, tracker, share, estimator, h, kappa, tau):
    """State space of one follower: s = [q_i, v_i, xi_hat (2), u_ff(k-1)],
    inputs w = [q_t, v_t, a_hat]; returns (As, Bs, Cs, Ds) with u = Cs s + Ds w."""
    G, Ge, L = p["G"][0], (p["Ge"][0] if tracker else np.zeros(2)), p["L"]
    a = np.exp(-T / tau) if tau > 0 else 0.0
    kp = G[0]
    # xi = Sx s + Wx w
    Sx = np.zeros((2, 5)); Sx[:, 0:2] = -np.eye(2)
    Wx = np.zeros((2, 3)); Wx[:, 0:2] = np.eye(2)
    # u_ff = Sf s + Wf w ; u_a = Sa s + Wa w ; u_h = Sh s
    Sf, Wf = np.zeros(5), np.zeros(3)
    if share:
        Sf[4], Wf[2] = a, (1.0 - a) * kappa
    Sa, Wa = Ge @ Sx, Ge @ Wx
    Sa[2:4] -= Ge
    Sh = np.zeros(5); Sh[1] = -kp * h
    Cs, Ds = G @ Sx + Sa + Sf + Sh, G @ Wx + Wa + Wf
    Phi, Gam = zoh(A, B, T)
    Pe, Qe = zoh(A - B @ G[None, :] + L, np.eye(2), T)
    As, Bs = np.zeros((5, 5)), np.zeros((5, 3))
    As[0:2] = Gam @ Cs[None, :]; As[0:2, 0:2] += Phi
    Bs[0:2] = Gam @ Ds[None, :]
    cs, cw = -L @ Sx - B @ (Sa + Sh)[None, :], -L @ Wx - B @ Wa[None, :]
    if share and estimator:   # the shared acceleration the command does not use: B (a_hat - u_ff)
        cs, cw = cs - B @ Sf[None, :], cw - B @ Wf[None, :]
        cw[:, 2] += B[:, 0]
    As[2:4] = Qe @ cs; As[2:4, 2:4] += Pe
    Bs[2:4] = Qe @ cw
    As[4], Bs[4] = Sf, Wf
    return As, Bs, Cs, Ds, Phi, Gam


def response(model, T, D, w):
    """Gamma(e^{j w T}) on the grid w (rad/s)."""
    As, Bs, Cs, Ds, Phi, Gam = model
    out = np.empty(w.size, dtype=complex)
    for k, om in enumerate(w):
        z = np.exp(1j * om * T)
        target = np.linalg.solve(z * np.eye(2) - Phi, Gam)[:, 0]
        inputs = np.concatenate([target, [z ** (-D)]])
        out[k] = Cs @ np.linalg.solve(z * np.eye(5) - As, Bs @ inputs) + Ds @ inputs
    return out


def impulse_l1(model, D, ticks):
    """sum_k |g_k| of the response of u_i to a unit u_t at tick 0."""
    As, Bs, Cs, Ds, Phi, Gam = model
    s, xt, total = np.zeros(5), np.zeros(2), 0.0
    for k in range(ticks):
        ut = 1.0 if k == 0 else 0.0
        w = np.array([xt[0], xt[1], 1.0 if k == D else 0.0])
        total += abs(Cs @ s + Ds @ w)
        s, xt = As @ s + Bs @ w, Phi @ xt + Gam[:, 0] * ut
    return total


def configurations(p):
    """(label, short label, tracker, share, estimator, h, kappa, tau, delays)."""
    return [
        ("paper's laws, nothing shared, tracker off", "paper's laws, tracker off",
         False, False, False, 0.0, 1.0, 0.0, (0.0,)),
        ("paper's laws, nothing shared, tracker on", "paper's laws, tracker on",
         True, False, False, 0.0, 1.0, 0.0, (0.0,)),
        ("paper's laws, a_t fed forward (command), tracker on", "paper's laws + a_t fed forward",
         True, True, False, 0.0, 1.0, 0.0, DELAYS),
        (f"chosen: h = {p['h']:g} s, kappa = {p['kappa']:g}, tau = {p['tau']:g} s, "
         "command + estimator, tracker on", f"chosen (h = {p['h']:g} s)",
         True, True, True, p["h"], p["kappa"], p["tau"], DELAYS),
    ]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scenario")
    ap.add_argument("--md", required=True)
    ap.add_argument("--png", required=True)
    args = ap.parse_args(argv)
    try:
        p = read(args.scenario)
    except (OSError, ValueError, KeyError, TypeError) as exc:
        print(f"string_stability_analysis: error: {exc}", file=sys.stderr)
        return 1
    lines = ["| configuration | rate (Hz) | delay | sup_ω \\|Γ\\| − 1 | at ω (rad/s) | ‖g‖₁ |",
             "|---|---:|---:|---:|---:|---:|"]
    fig, axes = plt.subplots(1, 2, figsize=(14, 5.5), sharey=True)
    for ax, rate in zip(axes, RATES):
        T = 1.0 / rate
        w = np.logspace(-2.5, np.log10(np.pi / T * 0.999), 1500)
        for label, short, tracker, share, est, h, kappa, tau, delays in configurations(p):
            model = loop(p, T, tracker, share, est, h, kappa, tau)
            for delay in delays:
                D = 1 if delay == "T" else int(round(delay * rate))
                g = np.abs(response(model, T, D, w))
                i = int(np.argmax(g))
                l1 = impulse_l1(model, D, int(round(60.0 * rate)))
                dtext = f"{D} T = {D * T * 1e3:g} ms"
                lines.append(f"| {label} | {rate:g} | {dtext} | {g[i] - 1:+.1e} | {w[i]:.3g} | "
                             f"{l1:.4f} |")
                if delay in (0.0, 0.1, 0.3) or not share:
                    style = "-" if "chosen" in label else ("--" if share else ":")
                    ax.semilogx(w, g, style, lw=1.6,
                                label=short + (f", delay {D * T * 1e3:g} ms" if share else ""))
        ax.axhline(1.0, color="black", lw=1.0)
        ax.set_title(f"|Γ(e^{{jωT}})| at {rate:g} Hz")
        ax.set_xlabel("ω (rad/s)")
        ax.set_ylim(0.0, 1.7)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("|Γ| = |U_i / U_{i−1}| = |Ξ_{i+1} / Ξ_i|")
    axes[1].legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    fig.savefig(args.png, dpi=110)
    with open(args.md, "w", encoding="utf-8") as fh:
        fh.write("\n".join(lines) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
