//! A uniform medium: gas at rest (with the static observers; the locally
//! non-rotating ones where the hole spins) filling the spherical shell
//! between two Boyer-Lindquist radii, with emission j_nu = j0 (nu /
//! nu_p)^-alpha and a grey absorption alpha_nu = k0, so its source
//! function is S_nu = (j0 / k0) (nu / nu_p)^-alpha. Where the laws of
//! transfer have closed forms: a chord of length L through it shows
//! S (1 - e^-k0 L), an optically thick shell its source function shifted
//! by the gravitational redshift, g^3 S(nu / g).

use crate::physics::kerr::Kerr;

/// The shell's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Uniform {
    /// Inner and outer radius (M).
    pub inner: f64,
    pub outer: f64,
    /// Both, where the gas ends.
    pub surfaces: [f64; 2],
    /// j_nu at nu_p (erg s^-1 cm^-3 Hz^-1 sr^-1).
    pub j0: f64,
    /// alpha_nu (cm^-1), the same at every frequency.
    pub k0: f64,
    /// Spectral index of the emission: j_nu ~ nu^-alpha.
    pub alpha: f64,
    /// The reference frequency (Hz).
    pub nu_p: f64,
}

crate::wgsl::gpu_block! {
    /// The shell as the GPU reads it (media.wgsl's uniform_*): the fields
    /// of [`Uniform`].
    UniformBlock {
        inner,
        outer,
        j0,
        k0,
        alpha,
        nu_p,
    }
}

impl Uniform {
    /// Its parameters for the GPU.
    pub fn gpu_block(&self) -> UniformBlock {
        let f = |x: f64| x as f32;
        UniformBlock {
            inner: f(self.inner),
            outer: f(self.outer),
            j0: f(self.j0),
            k0: f(self.k0),
            alpha: f(self.alpha),
            nu_p: f(self.nu_p),
        }
    }
}

impl Uniform {
    /// The shell between `inner` and `outer` (M), emitting j0 (nu /
    /// nu_p)^-alpha and absorbing k0.
    pub fn new(inner: f64, outer: f64, (j0, k0): (f64, f64), alpha: f64, nu_p: f64) -> Uniform {
        Uniform {
            inner,
            outer,
            surfaces: [inner, outer],
            j0,
            k0,
            alpha,
            nu_p,
        }
    }

    /// Whether (r) lies in the shell.
    #[inline]
    pub fn contains(&self, r: f64) -> bool {
        (self.inner..=self.outer).contains(&r)
    }

    /// The length (M) over which it changes: none inside, so the shell's
    /// own thickness, and the distance to its surfaces outside it so that
    /// no piece steps over it.
    #[inline]
    pub fn scale(&self, r: f64) -> f64 {
        let thickness = self.outer - self.inner;
        if self.contains(r) {
            thickness
        } else {
            thickness.max((r - self.outer).max(self.inner - r))
        }
    }

    /// The frequency the gas at (r, cos th) measures for a photon of unit
    /// energy at infinity and angular momentum `lz` (M units) around the
    /// hole `kerr`: (1 - omega lz) / alpha of the locally non-rotating
    /// observer (1 / sqrt(1 - 2/r) at spin 0; [`Kerr::zamo_sky_shift`]).
    /// None inside the horizon, where no gas is at rest.
    #[inline]
    pub fn frequency_ratio(&self, kerr: Kerr, r: f64, cos_th: f64, lz: f64) -> Option<f64> {
        let sin = (1.0 - cos_th * cos_th).max(0.0).sqrt();
        let z = kerr.zamo_at(r, cos_th, sin);
        (z.alpha > 0.0).then(|| (1.0 - z.omega * lz) / z.alpha)
    }

    /// (j_nu, alpha_nu) in cgs at gas-frame frequency `nu`.
    #[inline]
    pub fn coefficients(&self, nu: f64) -> (f64, f64) {
        (self.j0 * (nu / self.nu_p).powf(-self.alpha), self.k0)
    }
}
