//! Small numerical tools: quadrature.

/// Nodes and weights of the n-point Gauss-Legendre rule on [-1, 1], by Newton iteration on the
/// Legendre polynomial P_n (Golub-Welsch would do as well; n is small here).
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    assert!(n >= 1);
    let mut nodes = vec![0.0; n];
    let mut weights = vec![0.0; n];
    for i in 0..n {
        // Initial guess (Tricomi): the i-th root from the right.
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut derivative = 0.0;
        for _ in 0..100 {
            // P_n(x) and P_n'(x) by the three-term recurrence.
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            // p1 = P_n(x), p0 = P_{n-1}(x) (also for n = 1).
            derivative = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / derivative;
            x -= dx;
            if dx.abs() < 1e-15 {
                break;
            }
        }
        nodes[i] = x;
        weights[i] = 2.0 / ((1.0 - x * x) * derivative * derivative);
    }
    (nodes, weights)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        // An n-point rule is exact for degree 2n - 1.
        for n in [1, 2, 5, 32, 64] {
            let (x, w) = gauss_legendre(n);
            let total: f64 = w.iter().sum();
            assert!((total - 2.0).abs() < 1e-12, "n {n}");
            let deg = 2 * n - 1;
            let integral: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(deg as i32 - 1)).sum();
            // int_{-1}^{1} x^(2n-2) dx = 2 / (2n - 1)
            assert!((integral - 2.0 / deg as f64).abs() < 1e-10, "n {n}: {integral}");
        }
    }
}
