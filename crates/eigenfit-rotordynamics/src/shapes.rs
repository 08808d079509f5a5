//! Mode shapes and orbits along the shaft: each shaft station's whirl ellipse of a damped mode
//! at one speed, normalised so that the largest ellipse has semi-major axis 1 and is at its
//! extreme at t = 0 (what a rotordynamicist draws beside a Campbell diagram).

use crate::error::RotorDynError;
use crate::modal::{Mode, Whirl};
use crate::rotor::Rotor;
use faer::c64;

/// One station's orbit, x(t) = Re(x e^{iωt}), y(t) = Re(y e^{iωt}): an ellipse, the sum of a
/// forward circle F e^{iωt} and a backward one B e^{−iωt} in the complex plane x + iy.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orbit {
    /// Complex amplitude of x.
    pub x: c64,
    /// Complex amplitude of y.
    pub y: c64,
}

impl Orbit {
    /// F = (x + iy)/2: the circle turning with the rotor (from x towards y).
    fn forward(&self) -> c64 {
        (self.x + c64::new(0.0, 1.0) * self.y) * 0.5
    }

    /// B = conj(x − iy)/2: the circle turning against the rotor.
    fn backward(&self) -> c64 {
        ((self.x - c64::new(0.0, 1.0) * self.y) * 0.5).conj()
    }

    /// Semi-major axis |F| + |B|.
    pub fn major(&self) -> f64 {
        self.forward().norm() + self.backward().norm()
    }

    /// Semi-minor axis |F| − |B|, signed: positive when the orbit turns forward (with the
    /// rotor, from x towards y), negative backward.
    pub fn minor(&self) -> f64 {
        self.forward().norm() - self.backward().norm()
    }

    /// Angle of the major axis from x towards y (rad, in (−π, π]; the axis, not a direction).
    pub fn angle(&self) -> f64 {
        0.5 * (self.forward().arg() + self.backward().arg())
    }

    /// The position at phase φ = ωt.
    pub fn at(&self, phase: f64) -> (f64, f64) {
        let e = c64::new(phase.cos(), phase.sin());
        ((self.x * e).re, (self.y * e).re)
    }

    /// The sense of the orbit as [`crate::modal::whirl_of`] reads one node: forward, backward,
    /// or [`Whirl::Mixed`] for a line (|minor/major| below its tolerance) or no motion.
    pub fn direction(&self) -> Whirl {
        let s = self.x.norm_sqr() + self.y.norm_sqr();
        if s == 0.0 {
            return Whirl::Mixed;
        }
        // −2 Im(x̄y)/(|x|² + |y|²) = (|F|² − |B|²)/(|F|² + |B|²): modal.rs's turn, its tolerance.
        let turn = -2.0 * (self.x.conj() * self.y).im / s;
        if turn.abs() <= crate::modal::WHIRL_TOLERANCE {
            Whirl::Mixed
        } else if turn > 0.0 {
            Whirl::Forward
        } else {
            Whirl::Backward
        }
    }

    fn scaled(&self, by: c64) -> Self {
        Self { x: self.x * by, y: self.y * by }
    }
}

/// One mode's shape: its orbit at every shaft node.
#[derive(Debug, Clone, PartialEq)]
pub struct ModeShape {
    /// Damped natural frequency (Hz).
    pub frequency_hz: f64,
    /// Whirl direction of the mode (as the mode lists give it).
    pub whirl: Whirl,
    /// Logarithmic decrement.
    pub log_dec: f64,
    /// Orbit of each shaft node, normalised: the largest has semi-major axis 1 and is at its
    /// extreme at t = 0.
    pub orbits: Vec<Orbit>,
    /// The node with the largest orbit.
    pub reference: usize,
}

impl ModeShape {
    /// The mode's orbits at the shaft nodes of `rotor`, normalised (see [`ModeShape::orbits`]).
    pub fn of(rotor: &Rotor, mode: &Mode) -> Self {
        let raw: Vec<Orbit> = (0..rotor.shaft_nodes())
            .map(|n| Orbit { x: mode.right[4 * n], y: mode.right[4 * n + 1] })
            .collect();
        let reference =
            (0..raw.len()).max_by(|&a, &b| raw[a].major().total_cmp(&raw[b].major())).unwrap_or(0);
        let r = raw[reference];
        // e^{iωt*} with ωt* = (arg B − arg F)/2 brings the reference's extreme to t = 0.
        let shift = 0.5 * (r.backward().arg() - r.forward().arg());
        let by = c64::new(shift.cos(), shift.sin()) * (1.0 / r.major().max(f64::MIN_POSITIVE));
        Self {
            frequency_hz: mode.frequency_hz(),
            whirl: mode.whirl,
            log_dec: mode.log_dec(),
            orbits: raw.iter().map(|o| o.scaled(by)).collect(),
            reference,
        }
    }

    /// Each node's semi-major axis, signed by where the node is at t = 0 along the reference
    /// orbit's major axis (+ on the reference's side, − opposite): the shape along the shaft,
    /// nodes of the mode where the sign changes.
    pub fn signed_major(&self) -> Vec<f64> {
        let theta = self.orbits[self.reference].angle();
        self.orbits
            .iter()
            .map(|o| {
                let (x, y) = o.at(0.0);
                let along = x * theta.cos() + y * theta.sin();
                if along < 0.0 {
                    -o.major()
                } else {
                    o.major()
                }
            })
            .collect()
    }
}

/// A marked station on the shaft: a bearing, seal or disk.
#[derive(Debug, Clone, PartialEq)]
pub struct Station {
    /// Its shaft node.
    pub node: usize,
    /// Its tag in the rotor file.
    pub tag: String,
}

/// The shapes and orbits of a rotor's lowest modes at one speed.
#[derive(Debug, Clone, PartialEq)]
pub struct RotorShapes {
    /// The speed (rpm).
    pub speed_rpm: f64,
    /// Axial position of each shaft node (m, from node 0).
    pub positions_m: Vec<f64>,
    /// Bearings and seals on the shaft (those on support nodes are not on it).
    pub bearings: Vec<Station>,
    /// Disks.
    pub disks: Vec<Station>,
    /// The modes, lowest damped frequency first.
    pub modes: Vec<ModeShape>,
}

impl RotorShapes {
    /// The `count` lowest modes of `rotor` at `speed_rpm`, by [`Rotor::lowest_modes`] (the
    /// mode lists' solver, whirl-frequency tables solved at each mode's own frequency). Fewer
    /// when the rotor has fewer oscillating modes; an error when it has none.
    pub fn of(rotor: &Rotor, speed_rpm: f64, count: usize) -> Result<Self, RotorDynError> {
        let modes = rotor.lowest_modes(crate::rpm_to_rad(speed_rpm), count)?;
        if modes.is_empty() {
            return Err(RotorDynError::Solver(format!("no oscillating mode at {speed_rpm} rpm")));
        }
        let on_shaft = |n: usize| n < rotor.shaft_nodes();
        Ok(Self {
            speed_rpm,
            positions_m: node_positions(rotor),
            bearings: rotor
                .bearings
                .iter()
                .filter(|b| on_shaft(b.n))
                .map(|b| Station { node: b.n, tag: b.tag.clone() })
                .collect(),
            disks: rotor.disks.iter().map(|d| Station { node: d.n, tag: d.tag.clone() }).collect(),
            modes: modes.iter().map(|m| ModeShape::of(rotor, m)).collect(),
        })
    }
}

/// Axial position of each shaft node: the running sum of element lengths (layered elements on
/// one node pair share it: the first one's length counts, as ROSS's `nodes_pos`).
pub fn node_positions(rotor: &Rotor) -> Vec<f64> {
    let mut z = vec![0.0; rotor.shaft_nodes()];
    let mut set = vec![false; rotor.shaft_nodes()];
    for s in &rotor.shafts {
        if !set[s.n + 1] {
            z[s.n + 1] = z[s.n] + s.length;
            set[s.n + 1] = true;
        }
    }
    z
}

#[cfg(test)]
mod tests {
    use super::*;

    /// x = cos ωt, y = sin ωt turns from x towards y: forward, a circle of radius 1.
    #[test]
    fn a_circle_turning_from_x_to_y_is_forward() {
        let o = Orbit { x: c64::new(1.0, 0.0), y: c64::new(0.0, -1.0) };
        assert!((o.major() - 1.0).abs() < 1e-15 && (o.minor() - 1.0).abs() < 1e-15);
        assert_eq!(o.direction(), Whirl::Forward);
        let (x, y) = o.at(0.1);
        assert!((x - 0.1f64.cos()).abs() < 1e-15 && (y - 0.1f64.sin()).abs() < 1e-15);
        let back = Orbit { x: o.x, y: -o.y };
        assert_eq!(back.direction(), Whirl::Backward);
        assert!((back.minor() + 1.0).abs() < 1e-15);
    }

    /// An ellipse of semi-axes 2 (along 0.6 rad) and 0.5, at its extreme at phase 0.4: major,
    /// minor and angle come back, and the largest distance over a fine sweep is the major.
    #[test]
    fn an_ellipse_gives_back_its_axes_and_angle() {
        let (a, b, th, p) = (2.0f64, 0.5f64, 0.6f64, 0.4f64);
        // Position u(t) = a cos(ωt − p) along the axis, v(t) = b sin(ωt − p) across it.
        let e = c64::new((-p).cos(), (-p).sin());
        let u = e * a;
        let v = e * c64::new(0.0, -b);
        let o = Orbit { x: u * th.cos() - v * th.sin(), y: u * th.sin() + v * th.cos() };
        assert!((o.major() - a).abs() < 1e-12, "{}", o.major());
        assert!((o.minor() - b).abs() < 1e-12, "{}", o.minor());
        let d = (o.angle() - th).rem_euclid(std::f64::consts::PI);
        assert!(d < 1e-12 || std::f64::consts::PI - d < 1e-12, "{}", o.angle());
        let far = (0..20_000)
            .map(|k| {
                let (x, y) = o.at(k as f64 * std::f64::consts::TAU / 20_000.0);
                x.hypot(y)
            })
            .fold(0.0, f64::max);
        assert!((far - a).abs() < 1e-6, "{far}");
    }
}
