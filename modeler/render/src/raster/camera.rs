//! Cameras: where the eyes are and where the screen is, and the projection that follows.
//!
//! Every view reduces to one model: an **eye** at `E` looking through a **screen rectangle**
//! (lower-left `pa`, lower-right `pb`, upper-left `pc`, in the world). The projection maps a
//! point onto that rectangle along the ray from the eye — the *generalised perspective* or
//! off-axis projection (Kooima 2008). With `vr`, `vu` the screen's unit right and up vectors,
//! `vn = vr × vu` its normal towards the eye, and for a point `p`, `q = p − E`:
//!
//! - depth `w = −vn·q` (distance in front of the eye, along the screen normal);
//! - the point's image on the screen plane, relative to the eye's foot: `(vr·q, vu·q)·d/w`
//!   with `d = vn·(E − pa)` the eye's distance to the screen;
//! - the screen spans `L = vr·(pa − E)` to `R = vr·(pb − E)` and `B = vu·(pa − E)` to
//!   `T = vu·(pc − E)`, so pixel `x = x0 + (vr·q·d/w − L)/(R − L)·width` and
//!   `y = y0 + (T − vu·q·d/w)/(T − B)·height` (rows down).
//!
//! Multiplied through by `w`, `X = x·w`, `Y = y·w` and `w` are linear in `p`: a 3 × 4 matrix,
//! [`Projection`]. The frustum is asymmetric whenever the eye is not in front of the screen's
//! centre — exactly the case of a tracked head in front of a display (fish-tank VR) and of each
//! eye of a stereo pair.
//!
//! - [`Orbit`]: a virtual camera circling a target, its screen the rectangle the field of view
//!   spans at the target's distance. Its stereo eyes sit ± half the separation along the camera's
//!   right vector and share that screen, so the target is at zero parallax (converged there).
//! - [`Tracked`]: the seed's set-up. The display is the ground plane: the terrain lies on its
//!   surface, heights come out of it towards the viewer, and the screen *is* the display, its
//!   physical size known. The head is tracked in the display's frame; the eyes are ± half the eye
//!   separation along the display's x axis (the head is assumed level with the display's rows).
//!
//! Both honour [`Camera::tilt`]: the seed's proposal for judging heights while pulling. The ground
//! plane turns about a horizontal axis (the camera's right vector through the pivot) so that its
//! near edge comes towards the viewer and its far edge sinks away: heights, which point almost
//! along the line of sight when one looks down on the display, turn towards the screen's up
//! direction and are seen in profile (a vertical pole at the pivot, seen from elevation `e`,
//! spans `cos(e − tilt)` of its length on screen instead of `cos e`). The light stays fixed to the
//! terrain, so tilting changes the view, not the shading.
//!
//! World coordinates are those of the mesh exports: `X = x` (along columns), `Y = height`,
//! `Z = y` (along rows), metres.

use glam::{DMat3, DVec3};

use crate::output::frame::RenderError;

/// A virtual camera circling a target point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orbit {
    /// The ground point looked at, `[x, y]` in metres.
    pub target: [f64; 2],
    /// The target's height, metres.
    pub target_height: f64,
    /// Angle of the eye around the target, radians: 0 = south of it (larger y; north is up on
    /// screen, as in the heightmap PNG), π/2 = east (larger x).
    pub azimuth: f64,
    /// Angle of the eye above the ground plane, radians (π/2 looks straight down).
    pub elevation: f64,
    /// Eye to target, metres; > 0.
    pub distance: f64,
    /// Vertical field of view, radians, in (0, π).
    pub fov_y: f64,
    /// Stereo eye separation as a fraction of `distance` (1/30 is the photographers' rule).
    pub separation: f64,
}

impl Orbit {
    /// [`Orbit::overview`]'s distance in ground half-diagonals: a square ground seen straight down
    /// spans `√2` half-diagonals, which a 45° field of view covers from 1.71.
    pub const OVERVIEW_DISTANCE: f64 = 1.75;

    /// Looks at the middle of `extent` (`[width, height]` of the ground, metres) at
    /// `azimuth`/`elevation` with a 45° field of view, from [`Orbit::OVERVIEW_DISTANCE`] times the
    /// ground's half-diagonal: far enough that a square ground fits a 16:9 frame seen from any
    /// direction above it, near enough that it fills most of the frame.
    pub fn overview(extent: [f64; 2], azimuth: f64, elevation: f64) -> Orbit {
        let fov_y = 45f64.to_radians();
        let distance = Orbit::OVERVIEW_DISTANCE * 0.5 * extent[0].hypot(extent[1]);
        Orbit {
            target: [0.5 * extent[0], 0.5 * extent[1]],
            target_height: 0.0,
            azimuth,
            elevation,
            distance,
            fov_y,
            separation: 1.0 / 30.0,
        }
    }

    /// Moves the target along the ground by `right` and `forward` metres as seen on screen.
    pub fn pan(&mut self, right: f64, forward: f64) {
        let (s, c) = self.azimuth.sin_cos();
        self.target[0] += right * c - forward * s;
        self.target[1] += -right * s - forward * c;
    }

    /// Multiplies the distance by `factor` (< 1 zooms in).
    pub fn zoom(&mut self, factor: f64) {
        self.distance *= factor;
    }

    /// Turns the eye around the target by `azimuth` and raises it by `elevation` radians
    /// (elevation kept within ±89°).
    pub fn rotate(&mut self, azimuth: f64, elevation: f64) {
        let limit = 89f64.to_radians();
        self.azimuth += azimuth;
        self.elevation = (self.elevation + elevation).clamp(-limit, limit);
    }

    fn check(&self) -> Result<(), RenderError> {
        let finite = [
            self.target[0],
            self.target[1],
            self.target_height,
            self.azimuth,
            self.elevation,
            self.distance,
            self.fov_y,
            self.separation,
        ]
        .iter()
        .all(|v| v.is_finite());
        if !finite {
            return Err(RenderError::Camera("orbit parameters must be finite"));
        }
        if self.distance <= 0.0 {
            return Err(RenderError::Camera("orbit distance must be positive"));
        }
        if self.fov_y <= 0.0 || self.fov_y >= std::f64::consts::PI {
            return Err(RenderError::Camera("field of view must be between 0 and 180°"));
        }
        Ok(())
    }
}

/// The seed's set-up: the terrain on a display of known size, seen from a tracked head.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tracked {
    /// Width and height of the display's picture, metres.
    pub display: [f64; 2],
    /// The head (midpoint between the eyes) in the display's frame, metres: x right, y up the
    /// display (towards its top edge), z out of it towards the viewer (> 0), origin at its centre.
    pub head: [f64; 3],
    /// Distance between the eyes, metres.
    pub eye_separation: f64,
    /// The ground point shown at the display's centre, `[x, y]` metres.
    pub centre: [f64; 2],
    /// Display metres per ground metre (the map scale); heights use it too.
    pub scale: f64,
}

impl Tracked {
    /// A display of `display` metres showing all of `extent` (ground metres), the head `distance`
    /// metres in front of its centre, and a 63 mm eye separation.
    pub fn fit(display: [f64; 2], extent: [f64; 2], distance: f64) -> Tracked {
        let scale = (display[0] / extent[0]).min(display[1] / extent[1]);
        Tracked {
            display,
            head: [0.0, 0.0, distance],
            eye_separation: 0.063,
            centre: [0.5 * extent[0], 0.5 * extent[1]],
            scale,
        }
    }

    fn check(&self) -> Result<(), RenderError> {
        let values = [
            self.display[0],
            self.display[1],
            self.head[0],
            self.head[1],
            self.head[2],
            self.eye_separation,
            self.centre[0],
            self.centre[1],
            self.scale,
        ];
        if !values.iter().all(|v| v.is_finite()) {
            return Err(RenderError::Camera("tracked view parameters must be finite"));
        }
        if self.display[0] <= 0.0 || self.display[1] <= 0.0 || self.scale <= 0.0 {
            return Err(RenderError::Camera("display size and scale must be positive"));
        }
        if self.head[2] <= 0.0 {
            return Err(RenderError::Camera("the head must be in front of the display (z > 0)"));
        }
        Ok(())
    }
}

/// Which view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum View {
    /// A virtual camera circling a target.
    Orbit(Orbit),
    /// A tracked head in front of the display the terrain lies on.
    Tracked(Tracked),
}

/// A view and the ground plane's tilt.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Where the eyes and the screen are.
    pub view: View,
    /// The ground plane's rotation towards the viewer, radians (0 = none): its near edge comes
    /// towards the viewer, its far edge sinks, heights turn into profile.
    pub tilt: f64,
}

impl Camera {
    /// An orbit camera framing a heightmap's ground (see [`Orbit::overview`]).
    pub fn overview(extent: [f64; 2], azimuth: f64, elevation: f64) -> Camera {
        Camera {
            view: View::Orbit(Orbit::overview(extent, azimuth, elevation)),
            tilt: 0.0,
        }
    }
}

/// Which eye to render.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Eye {
    /// The centre (mono) eye.
    Centre,
    /// The left eye.
    Left,
    /// The right eye.
    Right,
}

/// A screen rectangle in the world and the eye looking through it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Viewpoint {
    /// The eye's position, world metres.
    pub eye: DVec3,
    /// The screen's lower-left corner.
    pub lower_left: DVec3,
    /// The screen's lower-right corner.
    pub lower_right: DVec3,
    /// The screen's upper-left corner.
    pub upper_left: DVec3,
    /// The point the ground tilts about.
    pub pivot: DVec3,
    /// The tilt's axis (unit).
    pub axis: DVec3,
    /// Distance of the near clipping plane in front of the eye, world metres.
    pub near: f64,
}

impl Viewpoint {
    /// The eye's distance from the screen's plane: every point of that plane is at this depth
    /// `w` ([`Projection`]'s `w` is the distance along the screen's normal).
    pub fn screen_distance(&self) -> f64 {
        let vr = (self.lower_right - self.lower_left).normalize();
        let vu = (self.upper_left - self.lower_left).normalize();
        vr.cross(vu).dot(self.eye - self.lower_left)
    }
}

fn world(ground: [f64; 2], height: f64) -> DVec3 {
    DVec3::new(ground[0], height, ground[1])
}

impl Camera {
    /// Checks the parameters: finite, positive sizes, the head in front of the display.
    pub fn check(&self) -> Result<(), RenderError> {
        if !self.tilt.is_finite() {
            return Err(RenderError::Camera("tilt must be finite"));
        }
        match &self.view {
            View::Orbit(o) => o.check(),
            View::Tracked(t) => t.check(),
        }
    }

    /// The eye and screen of `eye`, for a frame of `aspect` = width / height (orbit views only:
    /// a tracked view's screen is the display).
    pub fn viewpoint(&self, eye: Eye, aspect: f64) -> Viewpoint {
        let side = match eye {
            Eye::Centre => 0.0,
            Eye::Left => -0.5,
            Eye::Right => 0.5,
        };
        match &self.view {
            View::Orbit(o) => {
                let (sa, ca) = o.azimuth.sin_cos();
                let (se, ce) = o.elevation.sin_cos();
                let target = world(o.target, o.target_height);
                let back = DVec3::new(ce * sa, se, ce * ca);
                let centre_eye = target + back * o.distance;
                let right = DVec3::new(ca, 0.0, -sa);
                let forward = -back;
                let up = right.cross(forward).normalize();
                let hh = o.distance * (0.5 * o.fov_y).tan();
                let hw = hh * aspect;
                Viewpoint {
                    eye: centre_eye + right * (side * o.separation * o.distance),
                    lower_left: target - right * hw - up * hh,
                    lower_right: target + right * hw - up * hh,
                    upper_left: target - right * hw + up * hh,
                    pivot: target,
                    axis: right,
                    near: (1e-3 * o.distance).max(1e-6),
                }
            }
            View::Tracked(t) => {
                // Display frame → world: x → +X, y (up the display) → −Z, z (out) → +Y.
                let s = 1.0 / t.scale;
                let centre = world(t.centre, 0.0);
                let to_world = |x: f64, y: f64, z: f64| centre + DVec3::new(x, z, -y) * s;
                let [w, h] = t.display;
                let [hx, hy, hz] = t.head;
                Viewpoint {
                    eye: to_world(hx + side * t.eye_separation, hy, hz),
                    lower_left: to_world(-0.5 * w, -0.5 * h, 0.0),
                    lower_right: to_world(0.5 * w, -0.5 * h, 0.0),
                    upper_left: to_world(-0.5 * w, 0.5 * h, 0.0),
                    pivot: centre,
                    axis: DVec3::X,
                    // 1 cm in front of the eye, in display metres.
                    near: 0.01 * s,
                }
            }
        }
    }
}

/// A pixel rectangle of the frame an eye is drawn into.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Viewport {
    /// First column.
    pub x: f64,
    /// First row.
    pub y: f64,
    /// Width, pixels.
    pub width: f64,
    /// Height, pixels.
    pub height: f64,
}

/// World point → `(X, Y, w)` with pixel `(X/w, Y/w)` and depth `w`: three rows of a 3 × 4
/// matrix, the tilt included.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    /// Rows for `X`, `Y` and `w`: `[a, b, c, d]` gives `a·X + b·Y + c·Z + d`.
    pub rows: [[f64; 4]; 3],
    /// The eye in the world (after undoing the tilt: the eye as the terrain sees it).
    pub eye: DVec3,
    /// The near plane's distance.
    pub near: f64,
}

impl Projection {
    /// The projection of `vp` onto `viewport`.
    pub fn new(vp: &Viewpoint, tilt: f64, viewport: Viewport) -> Projection {
        let vr = (vp.lower_right - vp.lower_left).normalize();
        let vu = (vp.upper_left - vp.lower_left).normalize();
        let vn = vr.cross(vu);
        let e = vp.eye;
        let d = vn.dot(e - vp.lower_left);
        let l = vr.dot(vp.lower_left - e);
        let r = vr.dot(vp.lower_right - e);
        let b = vu.dot(vp.lower_left - e);
        let t = vu.dot(vp.upper_left - e);
        // In eye coordinates q = p − E: X = ax·(vr·q) + bx·w, Y = bx'·w − ay·(vu·q), w = −vn·q.
        let ax = d * viewport.width / (r - l);
        let bx = viewport.x - l * viewport.width / (r - l);
        let ay = d * viewport.height / (t - b);
        let by = viewport.y + t * viewport.height / (t - b);
        let x_row = vr * ax - vn * bx;
        let y_row = -vu * ay - vn * by;
        let w_row = -vn;
        // Model: p' = pivot + R(p − pivot); rows act on p' − E = R p + (pivot − R pivot − E).
        // Negative about the right axis: the near edge (towards the eye) rises.
        let rot = DMat3::from_axis_angle(vp.axis, -tilt);
        let offset = vp.pivot - rot * vp.pivot - e;
        let row = |v: DVec3| {
            let m = rot.transpose() * v;
            [m.x, m.y, m.z, v.dot(offset)]
        };
        Projection {
            rows: [row(x_row), row(y_row), row(w_row)],
            eye: rot.transpose() * (e - vp.pivot) + vp.pivot,
            near: vp.near,
        }
    }

    /// The matrix as `M` (the rows' first three columns) and `t` (their last): `(X, Y, w) =
    /// M·p + t`.
    pub fn parts(&self) -> (DMat3, DVec3) {
        let r = &self.rows;
        (
            DMat3::from_cols(
                DVec3::new(r[0][0], r[1][0], r[2][0]),
                DVec3::new(r[0][1], r[1][1], r[2][1]),
                DVec3::new(r[0][2], r[1][2], r[2][2]),
            ),
            DVec3::new(r[0][3], r[1][3], r[2][3]),
        )
    }

    /// `(X, Y, w)` of a world point.
    pub fn apply(&self, p: DVec3) -> [f64; 3] {
        self.rows.map(|r| r[0] * p.x + r[1] * p.y + r[2] * p.z + r[3])
    }

    /// The pixel position and depth of a world point, `None` at or behind the eye.
    pub fn pixel(&self, p: DVec3) -> Option<[f64; 3]> {
        let [x, y, w] = self.apply(p);
        (w > 0.0).then(|| [x / w, y / w, w])
    }
}
