//! The check of `fx_env_lobe_spread` (shaders/render/environment.wgsl): the
//! shader reads the specular map between two levels with a fraction linear in
//! the spread of the prefiltered lobe, 1 − its mean cosine about its centre,
//! from a rational fit in α = roughness². Here the fit (the same constants) is
//! compared with the integral, by quadrature, that it stands for.

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    /// The shader's fit, with the shader's constants.
    const FIT: [f64; 6] = [30.124, 9.4665, 1.4145, 8.8945, 3.2514, 46.424];

    fn fit(roughness: f64) -> f64 {
        let [c0, c1, c2, c3, c4, c5] = FIT;
        let a = (roughness * roughness).max(1e-3);
        let sa = a.sqrt();
        a * a * (c0 - c1 * sa + c2 * a) / (1.0 + c3 * sa + c4 * a + c5 * a * a)
    }

    /// 1 − the mean cosine about the centre of the prefiltered lobe (the glTF
    /// BRDF's f cos at n = v: `D(n·h) G1(n·l)`, h = normalize(n + l), the
    /// weights of prefilter.wgsl), by the midpoint rule in θ (the lobe is
    /// symmetric about its centre).
    fn integral(roughness: f64) -> f64 {
        let a = (roughness * roughness).max(1e-3);
        let a2 = a * a;
        let steps = 20_000;
        let dt = 0.5 * PI / steps as f64;
        let (mut w, mut wc) = (0.0, 0.0);
        for i in 0..steps {
            let t = (i as f64 + 0.5) * dt;
            let c = t.cos();
            let ndh = (0.5 * t).cos();
            let dd = ndh * ndh * (a2 - 1.0) + 1.0;
            let d = a2 / (PI * dd * dd);
            let g1 = 2.0 / (1.0 + (1.0 + a2 * (1.0 - c * c) / (c * c)).sqrt());
            let k = d * g1 * t.sin();
            w += k;
            wc += k * c;
        }
        1.0 - wc / w
    }

    #[test]
    fn the_shaders_lobe_spread_fits_the_integral() {
        let mut worst = 0.0f64;
        // from roughness 0.05 on (4 % at 0.03, where alpha reaches its floor
        // of 1e-3: a lobe narrower than level 0's texels, read from level 0)
        for i in 5..=100 {
            let r = i as f64 / 100.0;
            let e = (fit(r) / integral(r) - 1.0).abs();
            worst = worst.max(e);
        }
        assert!(worst < 0.01, "largest relative error {worst}");
    }

    #[test]
    fn the_shader_holds_the_checked_constants() {
        let wgsl = include_str!("../../../shaders/render/environment.wgsl");
        let [c0, c1, c2, c3, c4, c5] = FIT;
        let line = format!(
            "a * a * ({c0} - {c1} * sa + {c2} * a) / (1.0 + {c3} * sa + {c4} * a + {c5} * a * a)"
        );
        assert!(wgsl.contains(&line), "environment.wgsl lacks `{line}`");
    }
}
