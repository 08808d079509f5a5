//! A two-plane rotor: elements on a line of nodes, its DOF numbering (x, y, α, β per shaft node,
//! then x, y per extra support node, as ROSS orders them) and its matrices at a speed.

use crate::band::{Assemble, Band};
use crate::elements::{Bearing, Disk, Mat8, PointMass, ShaftElement};
use crate::error::RotorDynError;
use crate::modal::{self, Mode, Quadratic};
use faer::Mat;

/// A rotor model.
#[derive(Debug, Clone, PartialEq)]
pub struct Rotor {
    /// Shaft elements, in node order.
    pub shafts: Vec<ShaftElement>,
    /// Disks.
    pub disks: Vec<Disk>,
    /// Bearings and seals.
    pub bearings: Vec<Bearing>,
    /// Point masses.
    pub point_masses: Vec<PointMass>,
    shaft_nodes: usize,
    /// Extra (support) nodes beyond the shaft, in increasing node number.
    extra_nodes: Vec<usize>,
}

/// Relative change of a mode's whirl frequency at which the fixed point is taken as reached.
pub const WHIRL_TOLERANCE: f64 = 1e-12;
/// Iterations per mode before the whirl-frequency fixed point is given up.
pub const WHIRL_MAX_ITERATIONS: usize = 200;
/// Modes solved beyond those asked for, so that a mode followed by MAC stays among the solved.
const WHIRL_SPARE_MODES: usize = 4;

/// The speed-independent part of the matrices, assembled once, in band storage (the band's
/// shape — the whole sparsity structure — is fixed by the rotor's layout, not by a speed).
#[derive(Debug, Clone)]
struct Fixed {
    m: Band,
    k: Band,
    c: Band,
    g: Band,
}

/// Mass, velocity and stiffness matrices at one speed, in band storage.
#[derive(Debug, Clone)]
struct BandMatrices {
    m: Band,
    d: Band,
    k: Band,
}

impl BandMatrices {
    fn quadratic(&self) -> Quadratic<'_> {
        Quadratic { m: &self.m, d: &self.d, k: &self.k }
    }
}

/// Mass, damping (C + ΩG), stiffness at one speed.
#[derive(Debug, Clone)]
pub struct Matrices {
    /// Mass M.
    pub m: Mat<f64>,
    /// Velocity matrix C + ΩG.
    pub d: Mat<f64>,
    /// Stiffness K.
    pub k: Mat<f64>,
    /// Gyroscopic matrix G (not multiplied by Ω).
    pub g: Mat<f64>,
}

impl Rotor {
    /// Notes for speeds (rpm) outside the speed range of the bearings' tabulated coefficients,
    /// one per range shared by several bearings: there the coefficients are the end pieces of
    /// the fitted curve, extrapolated (as ROSS does), and may be far from any real bearing —
    /// ROSS's own compressor (tables over 3000–11 000 rpm) gets negative stiffness and modes
    /// with negative damping at standstill.
    pub fn extrapolation_notes(&self, speeds_rpm: &[f64]) -> Vec<String> {
        let mut ranges: Vec<((f64, f64), Vec<&str>)> = Vec::new();
        for b in &self.bearings {
            let range =
                b.k.iter()
                    .chain(&b.c)
                    .chain(&b.m)
                    .find_map(|c| c.speed_range())
                    .map(|(lo, hi)| (crate::rad_to_rpm(lo), crate::rad_to_rpm(hi)));
            let Some(range) = range else { continue };
            match ranges.iter_mut().find(|(r, _)| *r == range) {
                Some((_, tags)) => tags.push(&b.tag),
                None => ranges.push((range, vec![&b.tag])),
            }
        }
        let mut notes = Vec::new();
        for ((lo, hi), tags) in ranges {
            let mut outside: Vec<f64> = speeds_rpm
                .iter()
                .copied()
                .filter(|&s| s < lo * (1.0 - 1e-9) || s > hi * (1.0 + 1e-9))
                .collect();
            outside.sort_by(f64::total_cmp);
            outside.dedup();
            if outside.is_empty() {
                continue;
            }
            let (a, b) =
                outside.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &s| (a.min(s), b.max(s)));
            let shown: Vec<&str> = tags.iter().take(4).copied().collect();
            let more = if tags.len() > 4 { format!(" and {} more", tags.len() - 4) } else { String::new() };
            let which = if outside.len() == 1 {
                format!("{a:.0} rpm lies")
            } else {
                format!("{} speeds from {a:.0} to {b:.0} rpm lie", outside.len())
            };
            notes.push(format!(
                "{which} outside the {lo:.0}–{hi:.0} rpm tables of {}{more}: their coefficients \
                 there are extrapolated (as ROSS does)",
                shown.join(", ")
            ));
        }
        notes
    }

    /// Builds a rotor, checking that every element sits on an existing node.
    pub fn new(
        mut shafts: Vec<ShaftElement>,
        disks: Vec<Disk>,
        bearings: Vec<Bearing>,
        point_masses: Vec<PointMass>,
    ) -> Result<Self, RotorDynError> {
        if shafts.is_empty() {
            return Err(RotorDynError::Model("the rotor has no shaft elements".into()));
        }
        shafts.sort_by_key(|s| s.n);
        // Several elements may share a node pair (ROSS's layered shafts: sleeves, fits); they add.
        let mut expected = 0;
        for s in &shafts {
            check_shaft(s)?;
            if s.n > expected {
                return Err(RotorDynError::Model(format!(
                    "shaft element `{}`: node {} leaves a gap: no shaft element starts at node {expected}",
                    s.tag, s.n
                )));
            }
            expected = s.n + 1;
        }
        let shaft_nodes = expected + 1;
        for d in &disks {
            if d.n >= shaft_nodes {
                return Err(RotorDynError::Model(format!(
                    "disk `{}`: node {} is not on the shaft (nodes 0–{})",
                    d.tag,
                    d.n,
                    shaft_nodes - 1
                )));
            }
            if !(d.m >= 0.0 && d.id >= 0.0 && d.ip >= 0.0) {
                return Err(RotorDynError::Model(format!("disk `{}`: m, Id, Ip must be ≥ 0", d.tag)));
            }
        }
        let mut extra: Vec<usize> = point_masses
            .iter()
            .map(|p| p.n)
            .chain(bearings.iter().filter_map(|b| b.n_link))
            .filter(|&n| n >= shaft_nodes)
            .collect();
        extra.sort_unstable();
        extra.dedup();
        for b in &bearings {
            // A bearing linking a node to itself adds its block and subtracts it again: it holds
            // nothing, and the rotor would be solved as if it were not there.
            if b.n_link == Some(b.n) {
                return Err(RotorDynError::Model(format!(
                    "bearing `{}`: n_link = n = {}: a bearing linking a node to itself holds nothing \
                     (link it to a support or pedestal node, or leave n_link out to ground it)",
                    b.tag, b.n
                )));
            }
            if b.n >= shaft_nodes && !extra.contains(&b.n) {
                return Err(RotorDynError::Model(format!(
                    "bearing `{}`: node {} is neither a shaft node (0–{}) nor a point mass node",
                    b.tag,
                    b.n,
                    shaft_nodes - 1
                )));
            }
        }
        for p in &point_masses {
            if !(p.mx >= 0.0 && p.my >= 0.0) {
                return Err(RotorDynError::Model(format!("point mass `{}`: masses must be ≥ 0", p.tag)));
            }
        }
        Ok(Rotor { shafts, disks, bearings, point_masses, shaft_nodes, extra_nodes: extra })
    }

    /// Number of degrees of freedom.
    pub fn dofs(&self) -> usize {
        4 * self.shaft_nodes + 2 * self.extra_nodes.len()
    }

    /// Number of shaft nodes.
    pub fn shaft_nodes(&self) -> usize {
        self.shaft_nodes
    }

    /// Index of the x DOF of a node (y follows it).
    pub fn x_dof(&self, node: usize) -> usize {
        if node < self.shaft_nodes {
            4 * node
        } else {
            let k = self.extra_nodes.iter().position(|&e| e == node).unwrap_or(0);
            4 * self.shaft_nodes + 2 * k
        }
    }

    /// Each shaft node's (x, y) DOFs, for the whirl direction.
    pub fn translation_pairs(&self) -> Vec<(usize, usize)> {
        (0..self.shaft_nodes).map(|n| (4 * n, 4 * n + 1)).collect()
    }

    /// How far from the diagonal any matrix entry lies: 7 within a shaft element (two nodes of
    /// four DOFs), more for a bearing linking a shaft node to a support node numbered after the
    /// shaft.
    fn half_bandwidth(&self) -> usize {
        let links = self
            .bearings
            .iter()
            .filter_map(|b| b.n_link.map(|l| self.x_dof(b.n).abs_diff(self.x_dof(l)) + 1));
        links.fold(7, usize::max).min(self.dofs().saturating_sub(1))
    }

    fn fixed(&self) -> Fixed {
        let (n, b) = (self.dofs(), self.half_bandwidth());
        let zero = Band::zeros(n, b, b);
        let mut f = Fixed { m: zero.clone(), k: zero.clone(), c: zero.clone(), g: zero };
        for s in &self.shafts {
            let o = 4 * s.n;
            scatter8(&mut f.m, o, &s.mass());
            scatter8(&mut f.k, o, &s.stiffness());
            scatter8(&mut f.g, o, &s.gyroscopic());
            scatter8(&mut f.c, o, &s.damping());
        }
        for d in &self.disks {
            let o = 4 * d.n;
            f.m.add(o, o, d.m);
            f.m.add(o + 1, o + 1, d.m);
            f.m.add(o + 2, o + 2, d.id);
            f.m.add(o + 3, o + 3, d.id);
            f.g.add(o + 2, o + 3, d.ip);
            f.g.add(o + 3, o + 2, -d.ip);
        }
        for p in &self.point_masses {
            let o = self.x_dof(p.n);
            f.m.add(o, o, p.mx);
            f.m.add(o + 1, o + 1, p.my);
        }
        f
    }

    /// Adds a bearing's 2×2 block (between its node and its link node, or to ground).
    pub fn add_bearing_block(&self, target: &mut impl Assemble, b: &Bearing, block: [[f64; 2]; 2]) {
        let i = self.x_dof(b.n);
        let link = b.n_link.map(|l| self.x_dof(l));
        for (r, row) in block.iter().enumerate() {
            for (c, &v) in row.iter().enumerate() {
                target.add(i + r, i + c, v);
                if let Some(j) = link {
                    target.add(j + r, j + c, v);
                    target.add(i + r, j + c, -v);
                    target.add(j + r, i + c, -v);
                }
            }
        }
    }

    /// The matrices at speed Ω (rad/s); bearing coefficients are taken at that speed (ROSS's
    /// default: excitation frequency = speed).
    pub fn matrices(&self, speed: f64) -> Matrices {
        self.matrices_from(&self.fixed(), speed, speed)
    }

    /// The matrices at speed Ω with the bearing coefficients at whirl frequency ω (rad/s).
    pub fn matrices_at(&self, speed: f64, whirl: f64) -> Matrices {
        self.matrices_from(&self.fixed(), speed, whirl)
    }

    /// Whether a bearing's coefficients depend on the whirl frequency (ROSS 3 tables over
    /// `frequency`, 2-D tables): then each mode is solved at its own whirl frequency.
    pub fn has_whirl_tables(&self) -> bool {
        self.bearings.iter().any(|b| b.k.iter().chain(&b.c).chain(&b.m).any(|c| c.depends_on_frequency()))
    }

    /// Notes for whirl frequencies (rad/s) outside the frequency tables of the bearings: there
    /// the coefficients are extrapolated linearly from the end slope (as ROSS 3 does).
    pub fn whirl_extrapolation_notes(&self, whirl: &[f64]) -> Vec<String> {
        let mut notes = Vec::new();
        for b in &self.bearings {
            let Some((lo, hi)) = b.k.iter().chain(&b.c).chain(&b.m).find_map(|c| c.frequency_range()) else {
                continue;
            };
            let outside: Vec<f64> =
                whirl.iter().copied().filter(|&w| w < lo * (1.0 - 1e-9) || w > hi * (1.0 + 1e-9)).collect();
            if outside.is_empty() {
                continue;
            }
            let hz = |w: f64| w / (2.0 * std::f64::consts::PI);
            let listed: Vec<String> = outside.iter().map(|&w| format!("{:.4} Hz", hz(w))).collect();
            notes.push(format!(
                "whirl frequencies {} lie outside the {:.4}–{:.4} Hz frequency table of {}: its coefficients \
                 there are extrapolated linearly from the end slope (as ROSS 3 does)",
                listed.join(", "),
                hz(lo),
                hz(hi),
                b.tag
            ));
        }
        notes
    }

    fn matrices_from(&self, f: &Fixed, speed: f64, whirl: f64) -> Matrices {
        let b = self.band_matrices(f, speed, whirl);
        Matrices { m: b.m.to_dense(), d: b.d.to_dense(), k: b.k.to_dense(), g: f.g.to_dense() }
    }

    /// M, C + ΩG and K at speed Ω with the bearing coefficients at whirl frequency ω, by band:
    /// O(n·b) per speed, nothing of size n².
    fn band_matrices(&self, f: &Fixed, speed: f64, whirl: f64) -> BandMatrices {
        let mut m = f.m.clone();
        let mut k = f.k.clone();
        let mut d = f.c.clone();
        for b in &self.bearings {
            self.add_bearing_block(&mut k, b, Bearing::block_at(&b.k, speed, whirl));
            self.add_bearing_block(&mut d, b, Bearing::block_at(&b.c, speed, whirl));
            self.add_bearing_block(&mut m, b, Bearing::block_at(&b.m, speed, whirl));
        }
        d.add_scaled(speed, &f.g);
        BandMatrices { m, d, k }
    }

    /// The oscillating modes at speed Ω (rad/s), ascending in damped frequency.
    pub fn modes(&self, speed: f64, with_left: bool) -> Result<Vec<Mode>, RotorDynError> {
        let mats = self.matrices(speed);
        self.modes_of(&mats, with_left)
    }

    /// Modes of already assembled matrices.
    pub fn modes_of(&self, mats: &Matrices, with_left: bool) -> Result<Vec<Mode>, RotorDynError> {
        modal::solve(mats.m.as_ref(), mats.d.as_ref(), mats.k.as_ref(), &self.translation_pairs(), with_left)
    }

    /// The `count` lowest modes of already assembled matrices with left vectors (for
    /// sensitivities), by the fastest exact route for the size.
    pub fn lowest_modes_of(&self, mats: &Matrices, count: usize) -> Result<Vec<Mode>, RotorDynError> {
        modal::solve_lowest(&mats.m, &mats.d, &mats.k, &self.translation_pairs(), count, true)
    }

    /// Whether the rotor is statically unstable at speed Ω (rad/s): the symmetric part of K has
    /// an eigenvalue (against M) below zero by more than its round-off bound — a negative
    /// bearing stiffness outweighing the shaft. Such a motion grows without oscillating (a real
    /// positive λ of the damped problem), so it is in no mode list: the reports say so instead
    /// of dropping it silently. Returns that eigenvalue ((rad/s)²).
    ///
    /// By band, without a dense solve: Sturm counts (the negative pivots of K − σM = LDLᵀ,
    /// Sylvester's law of inertia) bound the largest eigenvalue ρ by doubling, say whether any
    /// lies below −1e3·ε·ρ (the reduced matrix's round-off ε‖A‖₂ times core's margin for
    /// "unstable"), and only then find the lowest by bisection. `None` too when M's symmetric
    /// part is not positive definite (the question has no answer).
    pub fn divergent(&self, speed: f64) -> Option<f64> {
        let b = self.band_matrices(&self.fixed(), speed, speed);
        let (k, m) = (b.k.symmetric_part(), b.m.symmetric_part());
        m.cholesky()?;
        let n = self.dofs();
        let mut scratch = Vec::new();
        let mut below = |sigma: f64| k.count_below(&m, sigma, &mut scratch);
        let scale = (k.amax() / m.amax()).max(f64::MIN_POSITIVE);
        let mut rho = scale;
        // Doubling from ‖K‖/‖M‖ to above every eigenvalue (a vanishing pivot: σ is one; go on).
        for _ in 0..2100 {
            if below(rho) == Some(n) {
                break;
            }
            rho *= 2.0;
        }
        let bound = 1e3 * f64::EPSILON * rho;
        // A vanishing pivot at −bound: an eigenvalue there, not below it by more than round-off.
        if below(-bound).unwrap_or(0) == 0 {
            return None;
        }
        let mut lo = -2.0 * bound;
        for _ in 0..2100 {
            if below(lo) == Some(0) {
                break;
            }
            lo *= 2.0;
        }
        // Bisection: the lowest eigenvalue lies in [lo, hi).
        let mut hi = -bound;
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if hi - lo <= 1e-13 * lo.abs() || mid == lo || mid == hi {
                break;
            }
            match below(mid) {
                Some(0) => lo = mid,
                _ => hi = mid,
            }
        }
        let lowest = 0.5 * (lo + hi);
        (lowest < -1e3 * f64::EPSILON * rho.max(lowest.abs())).then_some(lowest)
    }

    /// How many rigid-body motions the rotor has with its bearing coefficients at speed Ω
    /// (rad/s): the modes of the undamped, non-spinning problem (symmetric parts of K and M)
    /// that core's scale-free test calls rigid-body
    /// ([`eigenfit_core::eigen::roundoff::rigid_body_modes`]) — 4 for a two-plane rotor without
    /// bearings or seals (two translations, two tilts), 0 for one held in both planes. Their
    /// zero eigenvalues are what the damped mode lists leave out ([`modal::rigid_body`]); how
    /// many of them round-off makes oscillating varies, this count does not.
    pub fn rigid_body_modes(&self, speed: f64) -> Result<usize, RotorDynError> {
        use eigenfit_core::eigen::{roundoff::rigid_body_modes, BandedSolver, EigenSolver};
        let b = self.band_matrices(&self.fixed(), speed, speed);
        let n = self.dofs();
        let system = eigenfit_core::matrix::System::banded(b.k.symmetric_part(), b.m.symmetric_part())
            .map_err(|e| RotorDynError::Model(e.to_string()))?;
        let mut count = n.min(12);
        loop {
            // A K that is not semi-definite (a negative bearing stiffness) has no rigid-body
            // motion to count: its divergent mode is another matter, said by the mode lists.
            let Ok(modes) = BandedSolver::default().lowest(&system, count) else { return Ok(0) };
            match rigid_body_modes(&system, &modes) {
                Some(flags) => return Ok(flags.iter().filter(|&&r| r).count()),
                // Every mode solved zero to round-off: more, up to all (then K is zero).
                None if count == n => return Ok(n),
                None => count = (2 * count).min(n),
            }
        }
    }

    /// The `count` lowest modes at speed Ω (rad/s), by the fastest exact route for the size.
    /// With whirl-frequency tables each mode is solved at its own whirl frequency
    /// ([`Rotor::matched_modes`]).
    pub fn lowest_modes(&self, speed: f64, count: usize) -> Result<Vec<Mode>, RotorDynError> {
        self.lowest_modes_over(&[speed], count).map(|mut all| all.remove(0))
    }

    /// The `count` lowest modes at several speeds, assembling the speed-independent part once.
    /// Speeds are solved in parallel (rayon; `RAYON_NUM_THREADS=1` for one thread), each on its
    /// own: the results do not depend on the number of threads.
    pub fn lowest_modes_over(&self, speeds: &[f64], count: usize) -> Result<Vec<Vec<Mode>>, RotorDynError> {
        use rayon::prelude::*;
        let f = self.fixed();
        let pairs = self.translation_pairs();
        let whirl = self.has_whirl_tables();
        speeds
            .par_iter()
            .map(|&s| {
                if whirl {
                    return self.matched_from(&f, &pairs, s, count);
                }
                let mats = self.band_matrices(&f, s, s);
                modal::solve_lowest_elastic(mats.quadratic(), &pairs, count, false).map(|(modes, _)| modes)
            })
            .collect()
    }

    /// The `count` lowest modes at speed Ω (rad/s), each with the bearing coefficients at its own
    /// whirl frequency (its damped natural frequency): from the synchronous solution, each mode is
    /// re-solved with the coefficients at its last frequency and followed by MAC until the
    /// frequency changes by less than [`WHIRL_TOLERANCE`] (ROSS 3's `matched_whirl=True`, whose
    /// default tolerance 1e-3 stops short of the fixed point). Sorted by frequency.
    pub fn matched_modes(&self, speed: f64, count: usize) -> Result<Vec<Mode>, RotorDynError> {
        self.matched_from(&self.fixed(), &self.translation_pairs(), speed, count)
    }

    fn matched_from(
        &self,
        f: &Fixed,
        pairs: &[(usize, usize)],
        speed: f64,
        count: usize,
    ) -> Result<Vec<Mode>, RotorDynError> {
        let solve = |whirl: f64| {
            let mats = self.band_matrices(f, speed, whirl);
            modal::solve_lowest_elastic(mats.quadratic(), pairs, count + WHIRL_SPARE_MODES, false)
                .map(|(modes, _)| modes)
        };
        let start = solve(speed)?;
        let mut out = Vec::with_capacity(count);
        for (i, first) in start.iter().take(count).enumerate() {
            let mut mode = first.clone();
            let mut converged = false;
            for _ in 0..WHIRL_MAX_ITERATIONS {
                let whirl = mode.eigenvalue.im;
                let candidates = solve(whirl)?;
                let next = candidates
                    .into_iter()
                    .map(|c| (crate::modal::mac(&mode.right, &c.right), c))
                    .max_by(|a, b| a.0.total_cmp(&b.0))
                    .map(|(_, c)| c)
                    .ok_or_else(|| RotorDynError::Solver(format!("no oscillating mode at {speed} rad/s")))?;
                let change = (next.eigenvalue.im - whirl).abs();
                mode = next;
                if change <= WHIRL_TOLERANCE * whirl.abs().max(mode.eigenvalue.im.abs()).max(1e-12) {
                    converged = true;
                    break;
                }
            }
            if !converged {
                return Err(RotorDynError::Solver(format!(
                    "mode {} at {:.6} rpm: the whirl frequency did not settle within {WHIRL_MAX_ITERATIONS} \
                     iterations (the bearing tables over frequency make it jump between modes)",
                    i + 1,
                    crate::rad_to_rpm(speed)
                )));
            }
            out.push(mode);
        }
        out.sort_by(|a, b| a.eigenvalue.im.total_cmp(&b.eigenvalue.im));
        Ok(out)
    }
}

fn scatter8(target: &mut impl Assemble, offset: usize, e: &Mat8) {
    for (i, row) in e.iter().enumerate() {
        for (j, v) in row.iter().enumerate() {
            target.add(offset + i, offset + j, *v);
        }
    }
}

fn check_shaft(s: &ShaftElement) -> Result<(), RotorDynError> {
    let bad = |what: &str| Err(RotorDynError::Model(format!("shaft element `{}`: {what}", s.tag)));
    let finite = [
        s.length,
        s.idl,
        s.odl,
        s.idr,
        s.odr,
        s.material.rho,
        s.material.e,
        s.material.g_s,
        s.axial_force,
        s.torque,
        s.alpha,
        s.beta,
    ];
    if finite.iter().any(|v| !v.is_finite()) {
        return bad("every number must be finite");
    }
    if s.length <= 0.0 {
        return bad("length L must be > 0");
    }
    if s.odl <= s.idl || s.odr <= s.idr || s.idl < 0.0 || s.idr < 0.0 {
        return bad("outer diameters must exceed inner diameters (≥ 0)");
    }
    if s.material.rho <= 0.0 || s.material.e <= 0.0 || s.material.g_s <= 0.0 {
        return bad("material rho, E and G_s must be > 0");
    }
    Ok(())
}
