//! `decompose`, `decompose_all` and nalgebra's `polar()` on the same 1,024 random sheared matrices (`T·R·U·K·Uᵀ`,
//! factors in [0.25, 4]), in 300 interleaved passes; prints each one's fastest pass per matrix and the ratios.
//!
//! On a machine shared with other work, criterion's estimates of the three move by 10–20 % from run to run, and not
//! together; the fastest of many interleaved passes is what each costs undisturbed, and a steadier ratio (see
//! `BENCHMARKS.md` §1). `cargo run --locked --profile bench --example decompose_interleaved`
use std::hint::black_box;
use std::time::Instant;

use bonescope::math::{decompose, decompose_all};
use glam::{DMat3, DMat4, DQuat, DVec3};

fn main() {
    let mut x: u64 = 0x5EED;
    let mut unit = || {
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        (x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    };
    let ms: Vec<DMat4> = (0..1024)
        .map(|_| {
            let mut q = || DQuat::from_xyzw(unit() - 0.5, unit() - 0.5, unit() - 0.5, unit() - 0.5).normalize();
            let (r, u) = (DMat3::from_quat(q()), DMat3::from_quat(q()));
            let k = DVec3::new(0.25 + 3.75 * unit(), 0.25 + 3.75 * unit(), 0.25 + 3.75 * unit());
            DMat4::from_mat3(r * u * DMat3::from_diagonal(k) * u.transpose())
        })
        .collect();
    let na: Vec<nalgebra::Matrix3<f64>> =
        ms.iter().map(|m| nalgebra::Matrix3::from_column_slice(&DMat3::from_mat4(*m).to_cols_array())).collect();
    let mut best = [f64::MAX; 3];
    for _ in 0..300 {
        let t = Instant::now();
        for m in &ms {
            black_box(decompose(black_box(m)));
        }
        best[0] = best[0].min(t.elapsed().as_secs_f64());
        let t = Instant::now();
        black_box(decompose_all(black_box(&ms)));
        best[1] = best[1].min(t.elapsed().as_secs_f64());
        let t = Instant::now();
        for m in &na {
            black_box(black_box(*m).polar());
        }
        best[2] = best[2].min(t.elapsed().as_secs_f64());
    }
    let ns = best.map(|b| b * 1e9 / 1024.0);
    println!(
        "single {:.0} ns, all {:.0} ns, nalgebra {:.0} ns: {:.2}x / {:.2}x",
        ns[0],
        ns[1],
        ns[2],
        ns[2] / ns[0],
        ns[2] / ns[1]
    );
}
