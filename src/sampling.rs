//! Random draws shared by the synthetic data, the virtual rig and the tests.

use rand::Rng;

/// One standard normal deviate by Box-Muller: two uniform draws `u1`, `u2` in [0, 1) from
/// `rng`, `sqrt(-2 ln u1) cos(2 pi u2)` (the cosine branch only; nothing is cached, so each
/// call takes exactly two draws). `u1` is floored at 1e-300 so the logarithm stays finite.
pub fn standard_normal<R: Rng + ?Sized>(rng: &mut R) -> f64 {
    let u1: f64 = rng.gen::<f64>().max(1e-300);
    let u2: f64 = rng.gen();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn zero_mean_unit_variance() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let n = 200_000;
        let xs: Vec<f64> = (0..n).map(|_| standard_normal(&mut rng)).collect();
        let mean = xs.iter().sum::<f64>() / n as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
        // Standard errors: 1/sqrt(n) = 0.0022 for the mean, sqrt(2/n) = 0.0032 for the variance.
        assert!(mean.abs() < 0.01, "{mean}");
        assert!((var - 1.0).abs() < 0.015, "{var}");
        // P(|x| > 1.96) = 5 %.
        let tail = xs.iter().filter(|x| x.abs() > 1.96).count() as f64 / n as f64;
        assert!((tail - 0.05).abs() < 0.003, "{tail}");
    }

    #[test]
    fn takes_two_draws_per_deviate() {
        let mut a = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        let mut b = a.clone();
        standard_normal(&mut a);
        let _: (f64, f64) = (b.gen(), b.gen());
        assert_eq!(a.gen::<u64>(), b.gen::<u64>());
    }
}
