//! The per-path medium stack: which dielectrics a ray travels inside, shared by both
//! tracers (the GPU twin is `MediumStack` in `shaders/medium.wgsl`).

/// How many nested dielectrics a [`MediumStack`] remembers.
pub const MEDIUM_STACK_SIZE: usize = 4;

/// The dielectrics a ray is inside, innermost last: the per-path medium stack that
/// lets dielectrics nest (glass in water, the camera inside glass).
///
/// The rule, for closed, properly nested (non-overlapping) dielectric surfaces:
/// - every path starts in air (index 1, an empty stack);
/// - a refracted ray that *enters* a dielectric (arrives on the side its geometric
///   normal points to) pushes the dielectric's index; the interface is
///   `eta_i` = the current medium's index, `eta_t` = the dielectric's;
/// - a refracted ray that *leaves* one pops the innermost entry; the interface is
///   `eta_i` = the dielectric's index, `eta_t` = the enclosing medium's, the entry below
///   the innermost (air when there is none, which is also the rule when leaving a
///   dielectric the path never entered, such as one around the camera);
/// - reflected and shadow rays keep the stack of the ray that spawned them.
///
/// Only the [`MEDIUM_STACK_SIZE`] outermost indices are stored; deeper nesting keeps
/// counting, and reads past the stored entries return the innermost one stored.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MediumStack {
    /// Indices of refraction, outermost first; entries at `depth` and beyond are unused.
    pub iors: [f64; MEDIUM_STACK_SIZE],
    /// Number of dielectrics the ray is inside.
    pub depth: u32,
}

impl MediumStack {
    /// The stack of a camera ray: in air, inside nothing.
    pub const AIR: Self = Self {
        iors: [1.0; MEDIUM_STACK_SIZE],
        depth: 0,
    };

    /// The stack of a ray inside the dielectrics of indices `iors`, outermost first.
    pub fn from_outermost_first(iors: &[f64]) -> Self {
        iors.iter().fold(Self::AIR, |stack, &ior| {
            stack.medium_after_refraction(true, ior)
        })
    }

    /// The index of refraction `level` dielectrics deep (0 = air, index 1).
    pub fn medium_ior_at(&self, level: u32) -> f64 {
        if level == 0 {
            1.0
        } else {
            self.iors[(level as usize).min(MEDIUM_STACK_SIZE) - 1]
        }
    }

    /// The index of the medium on the outside of a dielectric surface hit by a ray
    /// with this stack: the current medium when `entering`, else the enclosing one.
    pub fn medium_outside_ior(&self, entering: bool) -> f64 {
        if entering {
            self.medium_ior_at(self.depth)
        } else {
            self.medium_ior_at(self.depth.saturating_sub(1))
        }
    }

    /// The stack of the refracted ray: `ior` pushed when `entering`, else popped.
    pub fn medium_after_refraction(&self, entering: bool, ior: f64) -> Self {
        let mut next = *self;
        if entering {
            if (next.depth as usize) < MEDIUM_STACK_SIZE {
                next.iors[next.depth as usize] = ior;
            }
            next.depth = next.depth.saturating_add(1);
        } else {
            next.depth = next.depth.saturating_sub(1);
        }
        next
    }
}
