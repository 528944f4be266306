"""Iterative LQR with box-constrained controls: DDP with the dynamics' first derivatives.

Each iteration (Li and Todorov 2004; Tassa, Erez and Todorov 2012; the control bounds as in
Tassa, Mansard and Todorov 2014):

1. linearize about the current trajectory: A_k = df/dx, B_k = df/du by `jax.jacfwd` of the
   problem's integrator step, and the costs' gradients and Hessians (Gauss-Newton for residual
   costs, `Problem`), all vmapped over time;
2. a backward Riccati pass (`lax.scan`, reversed) from V = the terminal cost's expansion:

       Q_x = l_x + A^T V_x,        Q_u = l_u + B^T V_x,
       Q_xx = l_xx + A^T V_xx A,   Q_uu = l_uu + B^T V_xx B + mu I,   Q_ux = l_ux + B^T V_xx A,

   the control step k_k minimizes the quadratic model 1/2 d^T Q_uu d + Q_u^T d within the bounds
   (a projected Newton method on the box, a fixed number of iterations), and the feedback
   K_k = -Q_uu_ff^-1 Q_ux on the controls it leaves free (zero rows on the clamped ones); the
   value function is carried back through the closed loop;
3. a forward pass u = clip(u_k + alpha k_k + K_k (x - x_k)) for several step lengths alpha at
   once (`vmap` over alpha), keeping the longest whose cost decrease is at least a fraction of
   the model's prediction;
4. mu, the regularization of Q_uu, shrinks after a success and grows after a failure (a Q_uu
   that is not positive definite, or no acceptable step).

The iterations are one `lax.while_loop`, so `solve` compiles once. It stops with success when an
accepted step lowers the cost by less than `tolerance` relative to it (or the model predicts
less), and with NOT_CONVERGED when `iterations` run out or mu passes its ceiling.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
from jax import Array

from mbjax.integrate.solution import Status
from mbjax.linalg import spd_solve
from mbjax.trajopt.problem import Problem
from mbjax.trajopt.result import AbstractSolver, Result, history

MU_MIN, MU_MAX, MU_FACTOR = 1e-9, 1e10, 10.0
ARMIJO = 1e-4             # accept a step whose decrease is this fraction of the predicted one


def box_qp(H: Array, g: Array, lower: Array, upper: Array, iterations: int):
    """(d, free): argmin 1/2 d^T H d + g^T d over lower <= d <= upper for a positive-definite H,
    by projected Newton steps on the controls not held at a bound (Bertsekas 1982), and the mask
    of the controls left free. Unbounded, one Newton step."""
    eye = jnp.eye(g.shape[0], dtype=H.dtype)

    def clamped(d):
        grad = H @ d + g
        return ((d <= lower) & (grad > 0)) | ((d >= upper) & (grad < 0))

    def newton(_, d):
        free = ~clamped(d)
        H_free = jnp.where(free[:, None] & free[None, :], H, eye)
        rhs = jnp.where(free, -(g + H @ jnp.where(free, 0.0, d)), d)
        return jnp.clip(spd_solve(H_free, rhs), lower, upper)

    d = jax.lax.fori_loop(0, iterations, newton, jnp.clip(spd_solve(H, -g), lower, upper))
    return d, ~clamped(d)


class ILQR(AbstractSolver):
    """See the module. `iterations`: at most this many; `tolerance`: the relative cost decrease
    below which it stops; `regularization`: mu's first value; `steps`: the step lengths alpha
    tried at once in each forward pass; `qp_iterations`: projected Newton steps of the bounded
    control step."""

    iterations: int = eqx.field(static=True, default=200)
    tolerance: float = 1e-8
    regularization: float = 1e-6
    steps: tuple = eqx.field(static=True, default=(1.0, 0.5, 0.25, 0.1, 0.03, 0.01, 1e-3))
    qp_iterations: int = eqx.field(static=True, default=8)

    def solve(self, problem: Problem, us: Array) -> Result:
        xs = problem.rollout(us)
        cost = problem.cost(xs, us)
        alphas = jnp.asarray(self.steps, cost.dtype)
        N, nx, nu = problem.horizon, problem.nx, problem.nu
        state = dict(xs=xs, us=us, cost=cost, mu=jnp.asarray(self.regularization, cost.dtype),
                     iteration=jnp.array(0), done=jnp.array(False), stalled=jnp.array(False),
                     costs=history(self.iterations + 1, cost),
                     K=jnp.zeros((N, nu, nx), cost.dtype))

        def iterate(s):
            k, K, decrease, ok = self._backward(problem, s["xs"], s["us"], s["mu"])
            trials = jax.vmap(lambda a: self._forward(problem, s["xs"], s["us"], k, K, a))(alphas)
            new_costs = trials[2]
            predicted = -(alphas * decrease[0] + alphas**2 * decrease[1])
            good = ok & jnp.isfinite(new_costs) & (s["cost"] - new_costs > ARMIJO * predicted)
            best = jnp.argmax(good)                       # the longest acceptable step
            accept = good[best]
            xs, us, cost = (jnp.where(accept, t[best], old) for t, old in
                            zip(trials, (s["xs"], s["us"], s["cost"]), strict=True))
            change = s["cost"] - cost
            # stationary: the model predicts (or the step made) a negligible decrease
            converged = ((ok & (-decrease[0] <= self.tolerance * jnp.abs(s["cost"])))
                         | (accept & (change <= self.tolerance * jnp.abs(cost))))
            mu = jnp.where(accept, jnp.maximum(s["mu"] / MU_FACTOR, MU_MIN), s["mu"] * MU_FACTOR)
            i = s["iteration"] + 1
            return dict(xs=xs, us=us, cost=cost, mu=mu, iteration=i, done=converged,
                        stalled=mu > MU_MAX, costs=s["costs"].at[i].set(cost),
                        K=jnp.where(accept, K, s["K"]))

        def running(s):
            return ~s["done"] & ~s["stalled"] & (s["iteration"] < self.iterations)

        s = jax.lax.while_loop(running, iterate, state)
        finite = jnp.isfinite(s["cost"]) & jnp.all(jnp.isfinite(s["xs"]))
        status = (jnp.where(s["done"], 0, int(Status.NOT_CONVERGED))
                  | jnp.where(finite, 0, int(Status.NONFINITE)))
        q, v = problem.split(s["xs"])
        return Result(qs=q, vs=v, us=s["us"], cost=s["cost"], costs=s["costs"],
                      iterations=s["iteration"], feedback=s["K"], status=status)

    def _backward(self, problem: Problem, xs: Array, us: Array, mu: Array):
        """(k, K, (sum k^T Q_u, sum 1/2 k^T Q_uu k), ok): the Riccati pass about (xs, us)."""
        steps = jnp.arange(problem.horizon)
        A, B = jax.vmap(jax.jacfwd(problem.step, argnums=(0, 1)))(xs[:-1], us, steps)
        lx, lu, lxx, lux, luu = jax.vmap(problem.stage_expansion)(xs[:-1], us)
        Vx, Vxx = problem.final_expansion(xs[-1])
        eye = jnp.eye(problem.nu, dtype=xs.dtype)

        def back(carry, inputs):
            Vx, Vxx = carry
            A, B, lx, lu, lxx, lux, luu, u = inputs
            Qx, Qu = lx + A.T @ Vx, lu + B.T @ Vx
            Qxx, Qux = lxx + A.T @ Vxx @ A, lux + B.T @ Vxx @ A
            Quu = luu + B.T @ Vxx @ B
            H = 0.5 * (Quu + Quu.T) + mu * eye
            k, free = box_qp(H, Qu, problem.lower - u, problem.upper - u, self.qp_iterations)
            H_free = jnp.where(free[:, None] & free[None, :], H, eye)
            K = jnp.where(free[:, None], -spd_solve(H_free, jnp.where(free[:, None], Qux, 0.0)),
                          0.0)
            Vx = Qx + K.T @ Quu @ k + K.T @ Qu + Qux.T @ k
            Vxx = Qxx + K.T @ Quu @ K + K.T @ Qux + Qux.T @ K
            return (Vx, 0.5 * (Vxx + Vxx.T)), (k, K, k @ Qu, 0.5 * k @ Quu @ k)

        _, (k, K, d1, d2) = jax.lax.scan(back, (Vx, Vxx), (A, B, lx, lu, lxx, lux, luu, us),
                                         reverse=True)
        ok = jnp.all(jnp.isfinite(k)) & jnp.all(jnp.isfinite(K))
        return k, K, (jnp.sum(d1), jnp.sum(d2)), ok

    @staticmethod
    def _forward(problem: Problem, xs: Array, us: Array, k: Array, K: Array, alpha: Array):
        """(xs, us, cost) of the closed-loop rollout with step length alpha."""
        def f(x, inputs):
            x_ref, u_ref, k_, K_, i = inputs
            u = jnp.clip(u_ref + alpha * k_ + K_ @ (x - x_ref), problem.lower, problem.upper)
            return problem.step(x, u, i), (x, u)

        x_end, (x_seq, u_seq) = jax.lax.scan(f, xs[0], (xs[:-1], us, k, K,
                                                        jnp.arange(problem.horizon)))
        x_new = jnp.concatenate([x_seq, x_end[None]])
        return x_new, u_seq, problem.cost(x_new, u_seq)
