//! The symbolic skill model of SEADS (SPEC §3.4–3.6): the forward model q(z_T | z_0, k), the
//! intrinsic reward with second-best normalisation and novelty bonus, and relabelling by assignment.
