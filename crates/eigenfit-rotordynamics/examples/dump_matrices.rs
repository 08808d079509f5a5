//! Prints a ROSS rotor file's M, K, C+ΩG, G at a speed (rad/s) as JSON, for comparing the
//! assembled matrices against ROSS's; with a third argument, the 8 lowest modes' whirl per node.
//!
//! `cargo run -p eigenfit-rotordynamics --example dump_matrices -- FILE SPEED [whirl]`
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let rotor = eigenfit_rotordynamics::ross_file::read(std::path::Path::new(&args[1])).unwrap();
    let w: f64 = args[2].parse().unwrap();
    let m = rotor.matrices(w);
    let dump = |a: &faer::Mat<f64>| -> Vec<Vec<f64>> {
        (0..a.nrows()).map(|i| (0..a.ncols()).map(|j| a[(i, j)]).collect()).collect()
    };
    let out = serde_json::json!({"M": dump(&m.m), "K": dump(&m.k), "D": dump(&m.d), "G": dump(&m.g)});
    if args.len() > 3 {
        for (i, md) in rotor.modes(w, false).unwrap().iter().take(8).enumerate() {
            let turns: Vec<String> = rotor
                .translation_pairs()
                .iter()
                .map(|&(a, b)| {
                    let (u, v) = (md.right[a], md.right[b]);
                    format!("{:.4}", -2.0 * (u.conj() * v).im / (u.norm_sqr() + v.norm_sqr()))
                })
                .collect();
            eprintln!("{i} {:.4} {:?} {:?}", md.frequency_hz(), md.whirl, turns);
        }
        return;
    }
    println!("{out}");
}
