//! Rotor elements and their lateral matrices (x, y, α, β per node; shaft along z), transcribed
//! from ROSS's element formulation so that the same rotor gives the same modes.

use crate::interpolation::Coefficient;

/// A shaft material.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// Density (kg/m³).
    pub rho: f64,
    /// Young's modulus (Pa).
    pub e: f64,
    /// Shear modulus (Pa).
    pub g_s: f64,
}

impl Material {
    /// Poisson's ratio E/(2G) − 1, as ROSS derives it.
    pub fn poisson(&self) -> f64 {
        self.e / (2.0 * self.g_s) - 1.0
    }
}

/// Shear coefficient formula of a Timoshenko element.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShearMethod {
    /// Cowper (1966), ROSS's default.
    Cowper,
    /// Hutchinson (2001).
    Hutchinson,
}

/// A (possibly tapered, possibly hollow) shaft element between nodes `n` and `n + 1`.
#[derive(Debug, Clone, PartialEq)]
pub struct ShaftElement {
    /// Name (ROSS tag).
    pub tag: String,
    /// Left node.
    pub n: usize,
    /// Length (m).
    pub length: f64,
    /// Inner and outer diameters at the left end (m).
    pub idl: f64,
    /// Outer diameter at the left end (m).
    pub odl: f64,
    /// Inner diameter at the right end (m).
    pub idr: f64,
    /// Outer diameter at the right end (m).
    pub odr: f64,
    /// Material.
    pub material: Material,
    /// Timoshenko shear deformation (false: Euler–Bernoulli).
    pub shear_effects: bool,
    /// Rotary inertia of the cross-sections.
    pub rotary_inertia: bool,
    /// Gyroscopic matrix.
    pub gyroscopic: bool,
    /// Shear coefficient formula.
    pub shear_method: ShearMethod,
    /// Axial force (N, tension positive).
    pub axial_force: f64,
    /// Torque (N·m).
    pub torque: f64,
    /// Proportional damping C = αM + βK.
    pub alpha: f64,
    /// Stiffness-proportional damping factor.
    pub beta: f64,
}

/// An 8×8 element matrix in the order x₀, y₀, α₀, β₀, x₁, y₁, α₁, β₁.
pub type Mat8 = [[f64; 8]; 8];

/// Section quantities shared by the element matrices (ROSS's names).
struct Section {
    a_l: f64,
    a: f64,
    ie_l: f64,
    ie: f64,
    phi: f64,
    a1: f64,
    a2: f64,
    b1: f64,
    b2: f64,
    gama: f64,
    delta: f64,
}

fn scaled(m: Mat8, s: f64) -> Mat8 {
    m.map(|row| row.map(|v| v * s))
}

fn add(a: &mut Mat8, b: &Mat8) {
    for i in 0..8 {
        for j in 0..8 {
            a[i][j] += b[i][j];
        }
    }
}

impl ShaftElement {
    fn section(&self) -> Section {
        use std::f64::consts::PI;
        let (idl, odl, idr, odr, l) = (self.idl, self.odl, self.idr, self.odr, self.length);
        let a_l = PI * (odl * odl - idl * idl) / 4.0;
        let ie_l = PI * (odl.powi(4) - idl.powi(4)) / 64.0;
        let (roj, rij, rok, rik) = (odl / 2.0, idl / 2.0, odr / 2.0, idr / 2.0);
        let dro = rok - roj;
        let dri = rik - rij;
        let a1 = 2.0 * PI * (roj * dro - rij * dri) / a_l;
        let a2 = PI * (roj.powi(3) * dro - rij.powi(3) * dri) / ie_l;
        let b1 = PI * (dro * dro - dri * dri) / a_l;
        let b2 = 3.0 * PI * (roj * roj * dro * dro - rij * rij * dri * dri) / (2.0 * ie_l);
        let gama = PI * (roj * dro.powi(3) - rij * dri.powi(3)) / ie_l;
        let delta = PI * (dro.powi(4) - dri.powi(4)) / (4.0 * ie_l);
        // Area and second moment at mid-element.
        let a = a_l * (1.0 + a1 * 0.5 + b1 * 0.25);
        let ie = ie_l * (1.0 + a2 * 0.5 + b2 * 0.25 + gama * 0.125 + delta * 0.0625);
        let phi = if self.shear_effects {
            let r = ((idl + idr) / 2.0) / ((odl + odr) / 2.0);
            let r2 = r * r;
            let r12 = (1.0 + r2) * (1.0 + r2);
            let nu = self.material.poisson();
            let kappa = match self.shear_method {
                ShearMethod::Hutchinson => {
                    6.0 * r12
                        * ((1.0 + nu)
                            / (r12 * (7.0 + 12.0 * nu + 4.0 * nu * nu)
                                + 4.0 * r2 * (5.0 + 6.0 * nu + 2.0 * nu * nu)))
                }
                ShearMethod::Cowper => {
                    6.0 * r12 * ((1.0 + nu) / (r12 * (7.0 + 6.0 * nu) + r2 * (20.0 + 12.0 * nu)))
                }
            };
            12.0 * self.material.e * ie / (self.material.g_s * kappa * a * l * l)
        } else {
            0.0
        };
        Section { a_l, a, ie_l, ie, phi, a1, a2, b1, b2, gama, delta }
    }

    /// Mass matrix (translational and, if enabled, rotary inertia).
    pub fn mass(&self) -> Mat8 {
        let s = self.section();
        let (phi, l, a1, b1) = (s.phi, self.length, s.a1, s.b1);
        let p2 = phi * phi;
        let m1 = (468.0 + 882.0 * phi + 420.0 * p2)
            + a1 * (108.0 + 210.0 * phi + 105.0 * p2)
            + b1 * (38.0 + 78.0 * phi + 42.0 * p2);
        let m2 = ((66.0 + 115.5 * phi + 52.5 * p2)
            + a1 * (21.0 + 40.5 * phi + 21.0 * p2)
            + b1 * (8.5 + 18.0 * phi + 10.5 * p2))
            * l;
        let m3 = (162.0 + 378.0 * phi + 210.0 * p2)
            + a1 * (81.0 + 189.0 * phi + 105.0 * p2)
            + b1 * (46.0 + 111.0 * phi + 63.0 * p2);
        let m4 = ((39.0 + 94.5 * phi + 52.5 * p2)
            + a1 * (18.0 + 40.5 * phi + 21.0 * p2)
            + b1 * (9.5 + 21.0 * phi + 10.5 * p2))
            * l;
        let m5 = ((12.0 + 21.0 * phi + 10.5 * p2)
            + a1 * (4.5 + 9.0 * phi + 5.25 * p2)
            + b1 * (2.0 + 4.5 * phi + 3.0 * p2))
            * l
            * l;
        let m6 = ((39.0 + 94.5 * phi + 52.5 * p2)
            + a1 * (21.0 + 54.0 * phi + 31.5 * p2)
            + b1 * (12.5 + 34.5 * phi + 21.0 * p2))
            * l;
        let m7 = ((9.0 + 21.0 * phi + 10.5 * p2)
            + a1 * (4.5 + 10.5 * phi + 5.25 * p2)
            + b1 * (2.5 + 6.0 * phi + 3.0 * p2))
            * l
            * l;
        let m8 = (468.0 + 882.0 * phi + 420.0 * p2)
            + a1 * (360.0 + 672.0 * phi + 315.0 * p2)
            + b1 * (290.0 + 540.0 * phi + 252.0 * p2);
        let m9 = ((66.0 + 115.5 * phi + 52.5 * p2)
            + a1 * (45.0 + 75.0 * phi + 31.5 * p2)
            + b1 * (32.5 + 52.5 * phi + 21.0 * p2))
            * l;
        let m10 = ((12.0 + 21.0 * phi + 10.5 * p2)
            + a1 * (7.5 + 12.0 * phi + 5.25 * p2)
            + b1 * (5.0 + 7.5 * phi + 3.0 * p2))
            * l
            * l;
        let mt = [
            [m1, 0.0, 0.0, m2, m3, 0.0, 0.0, -m4],
            [0.0, m1, -m2, 0.0, 0.0, m3, m4, 0.0],
            [0.0, -m2, m5, 0.0, 0.0, -m6, -m7, 0.0],
            [m2, 0.0, 0.0, m5, m6, 0.0, 0.0, -m7],
            [m3, 0.0, 0.0, m6, m8, 0.0, 0.0, -m9],
            [0.0, m3, -m6, 0.0, 0.0, m8, m9, 0.0],
            [0.0, m4, -m7, 0.0, 0.0, m9, m10, 0.0],
            [-m4, 0.0, 0.0, -m7, -m9, 0.0, 0.0, m10],
        ];
        let rho = self.material.rho;
        let mut m = scaled(mt, rho * s.a_l * l / (1260.0 * (1.0 + phi).powi(2)));
        if self.rotary_inertia {
            let mr = scaled(self.rotary_pattern(&s), rho * s.ie_l / (210.0 * l * (1.0 + phi).powi(2)));
            add(&mut m, &mr);
        }
        m
    }

    /// The rotary-inertia pattern (ROSS's m11…m16); the gyroscopic matrix uses the same numbers.
    fn rotary_coefficients(&self, s: &Section) -> [f64; 6] {
        let (phi, l, a2, b2, g, d) = (s.phi, self.length, s.a2, s.b2, s.gama, s.delta);
        let p2 = phi * phi;
        let c1 = 252.0 + 126.0 * a2 + 72.0 * b2 + 45.0 * g + 30.0 * d;
        let c2 = (21.0 - 105.0 * phi
            + a2 * (21.0 - 42.0 * phi)
            + b2 * (15.0 - 21.0 * phi)
            + g * (10.5 - 12.0 * phi)
            + d * (7.5 - 7.5 * phi))
            * l;
        let c3 = (21.0
            - 105.0 * phi
            - 63.0 * a2 * phi
            - b2 * (6.0 + 42.0 * phi)
            - g * (7.5 + 30.0 * phi)
            - d * (7.5 + 22.5 * phi))
            * l;
        let c4 = (28.0
            + 35.0 * phi
            + 70.0 * p2
            + a2 * (7.0 - 7.0 * phi + 17.5 * p2)
            + b2 * (4.0 - 7.0 * phi + 7.0 * p2)
            + g * (2.75 - 5.0 * phi + 3.5 * p2)
            + d * (2.0 - 3.5 * phi + 2.0 * p2))
            * l
            * l;
        let c5 = (7.0 + 35.0 * phi - 35.0 * p2
            + a2 * (3.5 + 17.5 * phi - 17.5 * p2)
            + b2 * (3.0 + 10.5 * phi - 10.5 * p2)
            + g * (2.75 + 7.0 * phi - 7.0 * p2)
            + d * (2.5 + 5.0 * phi - 5.0 * p2))
            * l
            * l;
        let c6 = (28.0
            + 35.0 * phi
            + 70.0 * p2
            + a2 * (21.0 + 42.0 * phi + 52.5 * p2)
            + b2 * (18.0 + 42.0 * phi + 42.0 * p2)
            + g * (16.25 + 40.0 * phi + 35.0 * p2)
            + d * (15.0 + 37.5 * phi + 30.0 * p2))
            * l
            * l;
        [c1, c2, c3, c4, c5, c6]
    }

    fn rotary_pattern(&self, s: &Section) -> Mat8 {
        let [m11, m12, m13, m14, m15, m16] = self.rotary_coefficients(s);
        [
            [m11, 0.0, 0.0, m12, -m11, 0.0, 0.0, m13],
            [0.0, m11, -m12, 0.0, 0.0, -m11, -m13, 0.0],
            [0.0, -m12, m14, 0.0, 0.0, m12, -m15, 0.0],
            [m12, 0.0, 0.0, m14, -m12, 0.0, 0.0, -m15],
            [-m11, 0.0, 0.0, -m12, m11, 0.0, 0.0, -m13],
            [0.0, -m11, m12, 0.0, 0.0, m11, m13, 0.0],
            [0.0, -m13, -m15, 0.0, 0.0, m13, m16, 0.0],
            [m13, 0.0, 0.0, -m15, -m13, 0.0, 0.0, m16],
        ]
    }

    /// Stiffness matrix (bending and shear, axial-force and torque terms).
    pub fn stiffness(&self) -> Mat8 {
        let s = self.section();
        let (phi, l, a1, a2, b1, b2, g, d) = (s.phi, self.length, s.a1, s.a2, s.b1, s.b2, s.gama, s.delta);
        let p2 = phi * phi;
        let k1 = 1260.0 + 630.0 * a2 + 504.0 * b2 + 441.0 * g + 396.0 * d;
        let k2 = (630.0 + 210.0 * a2 + 147.0 * b2 + 126.0 * g + 114.0 * d
            - phi * (105.0 * a2 + 105.0 * b2 + 94.5 * g + 84.0 * d))
            * l;
        let k3 = (630.0
            + 420.0 * a2
            + 357.0 * b2
            + 315.0 * g
            + 282.0 * d
            + phi * (105.0 * a2 + 105.0 * b2 + 94.5 * g + 84.0 * d))
            * l;
        let k4 = (420.0
            + 210.0 * phi
            + 105.0 * p2
            + a2 * (105.0 + 52.5 * p2)
            + b2 * (56.0 - 35.0 * phi + 35.0 * p2)
            + g * (42.0 - 42.0 * phi + 26.25 * p2)
            + d * (36.0 - 42.0 * phi + 21.0 * p2))
            * l
            * l;
        let k5 = (210.0 - 210.0 * phi - 105.0 * p2
            + a2 * (105.0 - 105.0 * phi - 52.5 * p2)
            + b2 * (91.0 - 70.0 * phi - 35.0 * p2)
            + g * (84.0 - 52.5 * phi - 26.25 * p2)
            + d * (78.0 - 42.0 * phi - 21.0 * p2))
            * l
            * l;
        let k6 = (420.0
            + 210.0 * phi
            + 105.0 * p2
            + a2 * (315.0 + 210.0 * phi + 52.5 * p2)
            + b2 * (266.0 + 175.0 * phi + 35.0 * p2)
            + g * (231.0 + 147.0 * phi + 26.25 * p2)
            + d * (204.0 + 126.0 * phi + 21.0 * p2))
            * l
            * l;
        let k7 = 12.0 + 6.0 * a1 + 4.0 * b1;
        let k8 = (6.0 + 3.0 * a1 + 2.0 * b1) * l;
        let k9 = (3.0 + 1.5 * a1 + b1) * l * l;
        let mut k = scaled(bending_pattern([k1, k2, k3, k4, k5, k6]), s.ie_l / 105.0);
        add(&mut k, &scaled(bending_pattern([k7, k8, k8, k9, k9, k9]), s.ie * phi * s.a_l / s.a));
        let mut k = scaled(k, self.material.e / l.powi(3) / (1.0 + phi).powi(2));
        if self.axial_force != 0.0 {
            let k10 = 36.0 + 60.0 * phi + 30.0 * p2;
            let k11 = 3.0 * l;
            let k12 = (4.0 + 5.0 * phi + 2.5 * p2) * l * l;
            let k13 = (1.0 + 5.0 * phi + 2.5 * p2) * l * l;
            let kaf = [
                [k10, 0.0, 0.0, k11, -k10, 0.0, 0.0, k11],
                [0.0, k10, -k11, 0.0, 0.0, -k10, -k11, 0.0],
                [0.0, -k11, k12, 0.0, 0.0, k11, -k13, 0.0],
                [k11, 0.0, 0.0, k12, -k11, 0.0, 0.0, -k13],
                [-k10, 0.0, 0.0, -k11, k10, 0.0, 0.0, -k11],
                [0.0, -k10, k11, 0.0, 0.0, k10, k11, 0.0],
                [0.0, -k11, -k13, 0.0, 0.0, k11, k12, 0.0],
                [k11, 0.0, 0.0, -k13, -k11, 0.0, 0.0, k12],
            ];
            add(&mut k, &scaled(kaf, self.axial_force / (30.0 * l * (1.0 + phi).powi(2))));
        }
        if self.torque != 0.0 {
            let h = l / 2.0;
            let ktq = [
                [0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1.0, 0.0],
                [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1.0],
                [1.0, 0.0, 0.0, -h, -1.0, 0.0, 0.0, h],
                [0.0, 1.0, h, 0.0, 0.0, -1.0, -h, 0.0],
                [0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0, 0.0],
                [0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0],
                [-1.0, 0.0, 0.0, -h, 1.0, 0.0, 0.0, h],
                [0.0, -1.0, h, 0.0, 0.0, 1.0, -h, 0.0],
            ];
            add(&mut k, &scaled(ktq, self.torque / l));
        }
        k
    }

    /// Gyroscopic matrix G (skew-symmetric), multiplied by Ω in the equations of motion.
    pub fn gyroscopic(&self) -> Mat8 {
        if !self.gyroscopic {
            return [[0.0; 8]; 8];
        }
        let s = self.section();
        let [g1, g2, g3, g4, g5, g6] = self.rotary_coefficients(&s);
        let g = [
            [0.0, g1, -g2, 0.0, 0.0, -g1, -g3, 0.0],
            [-g1, 0.0, 0.0, -g2, g1, 0.0, 0.0, -g3],
            [g2, 0.0, 0.0, g4, -g2, 0.0, 0.0, -g5],
            [0.0, g2, -g4, 0.0, 0.0, -g2, g5, 0.0],
            [0.0, -g1, g2, 0.0, 0.0, g1, g3, 0.0],
            [g1, 0.0, 0.0, g2, -g1, 0.0, 0.0, g3],
            [g3, 0.0, 0.0, -g5, -g3, 0.0, 0.0, g6],
            [0.0, g3, g5, 0.0, 0.0, -g3, -g6, 0.0],
        ];
        scaled(g, self.material.rho * s.ie_l * 2.0 / (210.0 * self.length * (1.0 + s.phi).powi(2)))
    }

    /// Proportional damping αM + βK.
    pub fn damping(&self) -> Mat8 {
        if self.alpha == 0.0 && self.beta == 0.0 {
            return [[0.0; 8]; 8];
        }
        let mut c = scaled(self.mass(), self.alpha);
        add(&mut c, &scaled(self.stiffness(), self.beta));
        c
    }
}

/// The bending stiffness pattern (ROSS's k1…k6 layout).
fn bending_pattern([k1, k2, k3, k4, k5, k6]: [f64; 6]) -> Mat8 {
    [
        [k1, 0.0, 0.0, k2, -k1, 0.0, 0.0, k3],
        [0.0, k1, -k2, 0.0, 0.0, -k1, -k3, 0.0],
        [0.0, -k2, k4, 0.0, 0.0, k2, k5, 0.0],
        [k2, 0.0, 0.0, k4, -k2, 0.0, 0.0, k5],
        [-k1, 0.0, 0.0, -k2, k1, 0.0, 0.0, -k3],
        [0.0, -k1, k2, 0.0, 0.0, k1, k3, 0.0],
        [0.0, -k3, k5, 0.0, 0.0, k3, k6, 0.0],
        [k3, 0.0, 0.0, k5, -k3, 0.0, 0.0, k6],
    ]
}

/// A rigid disk at a node.
#[derive(Debug, Clone, PartialEq)]
pub struct Disk {
    /// Name (ROSS tag).
    pub tag: String,
    /// Node.
    pub n: usize,
    /// Mass (kg).
    pub m: f64,
    /// Diametral moment of inertia (kg·m²).
    pub id: f64,
    /// Polar moment of inertia (kg·m²).
    pub ip: f64,
}

/// A point mass (x, y only), usually the support mass behind a bearing (`n_link`).
#[derive(Debug, Clone, PartialEq)]
pub struct PointMass {
    /// Name (ROSS tag).
    pub tag: String,
    /// Node (a shaft node or an extra support node).
    pub n: usize,
    /// Mass in x (kg).
    pub mx: f64,
    /// Mass in y (kg).
    pub my: f64,
}

/// The eight dynamic coefficients of a bearing or seal plus its added masses.
#[derive(Debug, Clone, PartialEq)]
pub struct Bearing {
    /// Name (ROSS tag), used in parameter names `kxx_<tag>`.
    pub tag: String,
    /// ROSS element class (BearingElement, SealElement, …).
    pub class: String,
    /// Node on the shaft.
    pub n: usize,
    /// Node it connects to (a point mass) or `None` for ground.
    pub n_link: Option<usize>,
    /// kxx, kxy, kyx, kyy (N/m) over speed.
    pub k: [Coefficient; 4],
    /// cxx, cxy, cyx, cyy (N·s/m) over speed.
    pub c: [Coefficient; 4],
    /// mxx, mxy, myx, myy (kg) over speed.
    pub m: [Coefficient; 4],
}

impl Bearing {
    /// 2×2 block [[xx, xy], [yx, yy]] of a coefficient set at speed Ω.
    pub fn block(set: &[Coefficient; 4], speed: f64) -> [[f64; 2]; 2] {
        Self::block_at(set, speed, speed)
    }

    /// 2×2 block of a coefficient set at speed Ω and whirl frequency ω.
    pub fn block_at(set: &[Coefficient; 4], speed: f64, whirl: f64) -> [[f64; 2]; 2] {
        let v = |i: usize| set[i].at_whirl(speed, whirl);
        [[v(0), v(1)], [v(2), v(3)]]
    }
}
