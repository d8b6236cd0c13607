/// \file
/// \brief The implicit steps' passes over a tether state's flat 3 × (N+1) arrays (the predictor,
/// the line search's trial iterate, the accelerations after a step, the finiteness sum) and over
/// its segments (the kept Newton matrix's branch check), written once over a pack type and
/// compiled twice as the force passes are (kelp/tether/force_pass_body.hpp):
/// kelp/tether/stepping.hpp includes this file in namespace `detail::step_baseline` with `vec` =
/// kelp::simd and, where kelp dispatches at run time (KELP_X86_DISPATCH), again in
/// `detail::step_avx2` with `vec` = kelp::simd::detail::avx2, inside KELP_AVX2_BEGIN / END. Their
/// element-wise results are the same bits on both. Not a header of its own: without
/// KELP_STEP_PASS_BODY defined it is empty, and it has no include guard on purpose.
#if defined(KELP_STEP_PASS_BODY)

/// The implicit step's predictor over the flat 3 × (N+1) arrays from index j on, in packets of P
/// (every argument by value: no reloads after the stores); returns where it stopped. Mode 3:
/// BDF2 (x̂ = (4x_n − x_{n−1})/3, v̂ likewise) from the accelerations a_n,
/// v = v_{n−1} + 2h a_n (`two_h` = 2h); 2: BDF2 with v = 2v_n − v_{n−1}; 1: backward Euler with
/// the velocity extrapolated; 0: backward Euler from v_n. x = x̂ + γh v in every mode.
template <int Mode, typename P, typename Scalar>
Eigen::Index predict_pass(Eigen::Index j, Eigen::Index len, Scalar four_thirds, Scalar third,
                          Scalar gh, Scalar two_h, const Scalar* xn, const Scalar* vn,
                          const Scalar* xp, const Scalar* vp, const Scalar* an, Scalar* x0,
                          Scalar* v0, Scalar* x1, Scalar* v1) {
  const P c43 = P::all(four_thirds), c13 = P::all(third), two = P::all(Scalar(2)), g = P::all(gh),
          h2 = P::all(two_h);
  for (; j + P::lanes <= len; j += P::lanes) {
    const P xnj = P::load(xn + j), vnj = P::load(vn + j);
    if constexpr (Mode >= 2) {
      const P vpj = P::load(vp + j);
      const P xh = c43 * xnj - c13 * P::load(xp + j);
      P vg;
      if constexpr (Mode == 3)
        vg = vpj + h2 * P::load(an + j);
      else
        vg = two * vnj - vpj;
      xh.store(x0 + j);
      (c43 * vnj - c13 * vpj).store(v0 + j);
      vg.store(v1 + j);
      (xh + g * vg).store(x1 + j);
    } else {
      P vg = vnj;
      if constexpr (Mode == 1) vg = two * vnj - P::load(vp + j);
      xnj.store(x0 + j);
      vnj.store(v0 + j);
      vg.store(v1 + j);
      (xnj + g * vg).store(x1 + j);
    }
  }
  return j;
}

/// After a converged BDF2 step, over the flat 3 × (N+1) arrays from index j to len in packets of
/// P: the new accelerations a = (v − v̂)·`inv_gh` into `a_new`, and, when `compare`, the squared
/// distances of the solution v from the step's two predictors, 2v_n − v_{n−1} into `lin` and
/// v_{n−1} + `two_h`·a_n into `leap` (lane-wise partial sums); returns where it stopped.
template <typename P, typename Scalar>
Eigen::Index acceleration_pass(Eigen::Index j, Eigen::Index len, bool compare, Scalar inv_gh,
                               Scalar two_h, const Scalar* vn, const Scalar* vp, const Scalar* an,
                               const Scalar* v0, const Scalar* v, Scalar* a_new, P& lin, P& leap) {
  const P g = P::all(inv_gh), h2 = P::all(two_h), two = P::all(Scalar(2));
  for (; j + P::lanes <= len; j += P::lanes) {
    const P vj = P::load(v + j);
    ((vj - P::load(v0 + j)) * g).store(a_new + j);
    if (compare) {
      const P vpj = P::load(vp + j);
      const P dl = vj - (two * P::load(vn + j) - vpj), da = vj - (vpj + h2 * P::load(an + j));
      lin += dl * dl;
      leap += da * da;
    }
  }
  return j;
}

/// The line search's trial iterate over the flat arrays from index j to `end` in packets of P:
/// v = v1 + α δ into `vs` and x = x̂ + γh v into `xs` (as Eigen writes them: the same bits);
/// returns where it stopped.
template <typename P, typename Scalar>
Eigen::Index trial_pass(Eigen::Index j, Eigen::Index end, Scalar alpha, Scalar gh, const Scalar* v1,
                        const Scalar* delta, const Scalar* x0, Scalar* vs, Scalar* xs) {
  const P a = P::all(alpha), g = P::all(gh);
  for (; j + P::lanes <= end; j += P::lanes) {
    const P v = P::load(v1 + j) + a * P::load(delta + j);
    v.store(vs + j);
    (P::load(x0 + j) + g * v).store(xs + j);
  }
  return j;
}

/// Whether the segments from s to `a.end` (of rest length `a.l`, none parted) are on the
/// branches `a.branch` holds (branches_are's codes), in packets of P: sets `match` false and
/// stops at the first packet with a segment off its branch; returns where it stopped.
template <typename P, typename Scalar>
Eigen::Index branch_pass(Eigen::Index s, const BranchArrays<Scalar>& a, bool& match) {
  const P l = P::all(a.l), from = P::all(a.taut_from), zero = P::all(Scalar(0)),
          one = P::all(Scalar(1)), two = P::all(Scalar(2));
  for (; s + P::lanes <= a.end; s += P::lanes) {
    const P ls = P::load(a.stretched + s);
    P b = vec::select(vec::greater(ls, l), two, one);
    if (a.clamp) b = vec::select(vec::greater(P::load(a.tension + s), zero), b, zero);
    if (a.banded) b = vec::select(vec::greater_equal(ls, from), two, b);
    const P br = P::load(a.branch + s);
    if (vec::any(vec::less(b, br) || vec::greater(b, br))) {
      match = false;
      return s;
    }
  }
  return s;
}

/// trial_pass over [begin, end): packets, then one by one.
template <typename Scalar>
void trial_all(Eigen::Index begin, Eigen::Index end, Scalar alpha, Scalar gh, const Scalar* v1,
               const Scalar* delta, const Scalar* x0, Scalar* vs, Scalar* xs) {
  const Eigen::Index j =
      trial_pass<vec::Pack<Scalar, true>>(begin, end, alpha, gh, v1, delta, x0, vs, xs);
  trial_pass<vec::Pack<Scalar, false>>(j, end, alpha, gh, v1, delta, x0, vs, xs);
}

/// branch_pass over `a`'s segments [a.begin, a.end): packets, then one by one.
template <typename Scalar>
bool branches_all(const BranchArrays<Scalar>& a) {
  bool match = true;
  const Eigen::Index s = branch_pass<vec::Pack<Scalar, true>>(a.begin, a, match);
  if (match) branch_pass<vec::Pack<Scalar, false>>(s, a, match);
  return match;
}

/// predict_pass over the whole arrays: packets, then one by one.
template <typename Scalar>
void predict_all(const PredictArrays<Scalar>& a) {
  const auto run = [&](auto mode) {
    constexpr int m = decltype(mode)::value;
    const Eigen::Index j = predict_pass<m, vec::Pack<Scalar, true>>(
        0, a.len, a.four_thirds, a.third, a.gh, a.two_h, a.xn, a.vn, a.xp, a.vp, a.an, a.x0, a.v0,
        a.x1, a.v1);
    predict_pass<m, vec::Pack<Scalar, false>>(j, a.len, a.four_thirds, a.third, a.gh, a.two_h, a.xn,
                                              a.vn, a.xp, a.vp, a.an, a.x0, a.v0, a.x1, a.v1);
  };
  switch (a.mode) {
    case 3:
      return run(std::integral_constant<int, 3>());
    case 2:
      return run(std::integral_constant<int, 2>());
    case 1:
      return run(std::integral_constant<int, 1>());
    default:
      return run(std::integral_constant<int, 0>());
  }
}

/// acceleration_pass over the whole arrays, comparing the predictors (when `a.compare`) on
/// [free0, free1), the free nodes' entries, into `a.lin` and `a.leap`.
template <typename Scalar>
void accelerations_all(AccelerationArrays<Scalar>& a) {
  using PW = vec::Pack<Scalar, true>;
  using P1 = vec::Pack<Scalar, false>;
  PW lin_w = PW::all(Scalar(0)), leap_w = lin_w;
  P1 lin_1 = P1::all(Scalar(0)), leap_1 = lin_1;
  const auto pass = [&](auto& lin, auto& leap, Eigen::Index from, Eigen::Index to, bool compare) {
    using P = std::decay_t<decltype(lin)>;
    return acceleration_pass<P>(from, to, compare, a.inv_gh, a.two_h, a.vn, a.vp, a.an, a.v0, a.v,
                                a.a_new, lin, leap);
  };
  // The kinematic ends (at most one column each side) without the comparison.
  pass(lin_1, leap_1, 0, a.free0, false);
  const Eigen::Index j = pass(lin_w, leap_w, a.free0, a.free1, a.compare);
  pass(lin_1, leap_1, j, a.free1, a.compare);
  pass(lin_1, leap_1, a.free1, a.len, false);
  a.lin = lin_w.sum() + lin_1.sum();
  a.leap = leap_w.sum() + leap_1.sum();
}

/// The sum of the `len` scalars of each of the K arrays `p` (of the same length), in 4 packets
/// side by side (4 independent chains of additions), then packet by packet, then the rest one
/// by one. Its bits depend on the packets' width: only its finiteness is used (all_finite_fast).
template <int K, typename Scalar>
Scalar flat_sum(const Scalar* const (&p)[K], Eigen::Index len) {
  using P = vec::Pack<Scalar, vec::vectorized<Scalar>>;
  constexpr Eigen::Index w = P::lanes;
  P a0 = P::all(Scalar(0)), a1 = a0, a2 = a0, a3 = a0;
  Eigen::Index j = 0;
  for (; j + 4 * w <= len; j += 4 * w)
    for (int k = 0; k < K; ++k) {
      a0 += P::load(p[k] + j);
      a1 += P::load(p[k] + j + w);
      a2 += P::load(p[k] + j + 2 * w);
      a3 += P::load(p[k] + j + 3 * w);
    }
  for (; j + w <= len; j += w)
    for (int k = 0; k < K; ++k) a0 += P::load(p[k] + j);
  Scalar s = ((a0 + a1) + (a2 + a3)).sum();
  for (; j < len; ++j)
    for (int k = 0; k < K; ++k) s += p[k][j];
  return s;
}

#endif  // KELP_STEP_PASS_BODY
