//! The keywords palpa reads, parsed into plain records in the deck's own units, and the verdict
//! on every other keyword. Card layouts follow the LS-DYNA Keyword User's Manual (R13/R14);
//! [`crate::scene`] gives the records their meaning in palpa.
//!
//! A keyword palpa does not know is an error that names it and its line, unless it only asks
//! for output or tunes the solver's bookkeeping (`*DATABASE_*`, `*CONTROL_OUTPUT`,
//! `*CONTROL_ENERGY`, `*CONTROL_CPU`, ...), which is a warning. A field palpa does not support
//! is an error when a value other than its default would change the physics, and a warning when
//! it only concerns LS-DYNA's algorithms or output.

use crate::card::{fields, Field, Fields};
use crate::lex::{Block, Card, Lexed, Loc};
use std::collections::BTreeMap;

/// An id as written: LS-DYNA allows character labels for parts, sections, materials and
/// hourglass cards; a numeric label is normalised (`007` is `7`).
pub type Key = String;

fn key(s: &str) -> Key {
    let t = s.trim();
    match t.parse::<i64>() {
        Ok(v) => v.to_string(),
        Err(_) => t.to_string(),
    }
}

/// `*NODE`.
#[derive(Clone, Debug)]
pub struct NodeCard {
    /// Node id.
    pub id: i64,
    /// Coordinates (deck units).
    pub x: [f64; 3],
    /// Coordinates as written (converted to SI from the text, see [`crate::units::Units::to_si_text`]).
    pub text: [Box<str>; 3],
    /// Translational constraint code TC (0 none, 1 x, 2 y, 3 z, 4 xy, 5 yz, 6 zx, 7 all).
    pub tc: i64,
    /// Where.
    pub at: Loc,
}

/// `*ELEMENT_SOLID` or `*ELEMENT_SHELL`.
#[derive(Clone, Debug)]
pub struct ElementCard {
    /// Element id.
    pub id: i64,
    /// Part id.
    pub part: Key,
    /// Node ids (8 for a solid, 4 for a shell).
    pub nodes: Vec<i64>,
    /// Where.
    pub at: Loc,
}

/// `*PART`.
#[derive(Clone, Debug)]
pub struct PartCard {
    /// Part id.
    pub id: Key,
    /// Heading.
    pub title: String,
    /// Section id.
    pub section: Key,
    /// Material id.
    pub material: Key,
    /// Hourglass card id (`0`: none).
    pub hourglass: Key,
    /// Where.
    pub at: Loc,
    /// `$palpa:` comments.
    pub palpa: Vec<(Loc, String)>,
}

/// `*SECTION_SOLID` / `*SECTION_SHELL`.
#[derive(Clone, Debug)]
pub struct SectionCard {
    /// ELFORM.
    pub elform: i64,
    /// Shell section (else solid).
    pub shell: bool,
    /// Shell thickness T1 (deck units; 0 for solids).
    pub thickness: f64,
    /// Where.
    pub at: Loc,
    /// `$palpa:` comments.
    pub palpa: Vec<(Loc, String)>,
}

/// A material card (deck units).
#[derive(Clone, Debug)]
pub enum MatKind {
    /// `*MAT_ELASTIC` (001).
    Elastic {
        /// Density.
        ro: f64,
        /// Young's modulus.
        e: f64,
        /// Poisson ratio.
        pr: f64,
    },
    /// `*MAT_OGDEN_RUBBER` (077_O).
    Ogden {
        /// Density.
        ro: f64,
        /// Poisson ratio.
        pr: f64,
        /// MU1.. (nonzero terms).
        mu: Vec<f64>,
        /// ALPHA1.. (same terms).
        alpha: Vec<f64>,
        /// Prony terms (GI, BETAI).
        prony: Vec<(f64, f64)>,
    },
    /// `*MAT_SIMPLIFIED_RUBBER/FOAM` (181).
    SimplifiedRubber {
        /// Density.
        ro: f64,
        /// Bulk modulus KM.
        km: f64,
        /// Damping coefficient MU.
        mu: f64,
        /// Shear modulus G.
        g: f64,
        /// Gauge length, width, thickness (SGL, SW, ST).
        gauge: [f64; 3],
        /// Load curve LC (force against change in gauge length), if any.
        lc: Option<Key>,
    },
    /// `*MAT_PIECEWISE_LINEAR_PLASTICITY` (024).
    Plasticity {
        /// Density.
        ro: f64,
        /// Young's modulus.
        e: f64,
        /// Poisson ratio.
        pr: f64,
        /// Yield stress SIGY.
        sigy: f64,
        /// Tangent modulus ETAN.
        etan: f64,
        /// Failure strain (FAIL > 0).
        fail: Option<f64>,
        /// Hardening curve LCSS, if any.
        lcss: Option<Key>,
        /// EPS1..8 / ES1..8 pairs (effective plastic strain, yield stress) given.
        table: Vec<(f64, f64)>,
    },
    /// `*MAT_RIGID` (020).
    Rigid {
        /// Density.
        ro: f64,
        /// Young's modulus (LS-DYNA's contact stiffness; palpa does not use it).
        e: f64,
        /// CMO (0: free, 1: constrained in global directions).
        cmo: f64,
        /// Translational constraint CON1.
        con1: i64,
        /// Rotational constraint CON2.
        con2: i64,
    },
}

/// A material card.
#[derive(Clone, Debug)]
pub struct MatCard {
    /// The law.
    pub kind: MatKind,
    /// The keyword as written (for messages).
    pub keyword: String,
    /// Where.
    pub at: Loc,
    /// `$palpa:` comments.
    pub palpa: Vec<(Loc, String)>,
}

/// `*HOURGLASS`.
#[derive(Clone, Debug)]
pub struct HourglassCard {
    /// IHQ (0: the `*CONTROL_HOURGLASS` default).
    pub ihq: i64,
    /// QM (None: default).
    pub qm: Option<f64>,
    /// Part bulk viscosity Q1, Q2 if given.
    pub q1q2: (Option<f64>, Option<f64>),
    /// Where.
    pub at: Loc,
    /// `$palpa:` comments.
    pub palpa: Vec<(Loc, String)>,
}

/// `*DEFINE_CURVE` (deck units, scale and offset not yet applied).
#[derive(Clone, Debug)]
pub struct CurveCard {
    /// SIDR.
    pub sidr: i64,
    /// Abscissa scale and offset: `x = SFA (a + OFFA)`.
    pub sfa: f64,
    /// Ordinate scale: `y = SFO (o + OFFO)`.
    pub sfo: f64,
    /// OFFA.
    pub offa: f64,
    /// OFFO.
    pub offo: f64,
    /// Points as written.
    pub points: Vec<(f64, f64)>,
    /// Title, if `_TITLE`.
    pub title: Option<String>,
    /// Where.
    pub at: Loc,
    /// `$palpa:` comments.
    pub palpa: Vec<(Loc, String)>,
}

impl CurveCard {
    /// The points with scale factors and offsets applied (deck units).
    pub fn scaled(&self) -> Vec<(f64, f64)> {
        self.points
            .iter()
            .map(|&(a, o)| (self.sfa * (a + self.offa), self.sfo * (o + self.offo)))
            .collect()
    }
}

/// A set of ids.
#[derive(Clone, Debug)]
pub struct SetCard {
    /// Members.
    pub ids: Vec<i64>,
    /// Title, if `_TITLE`.
    pub title: Option<String>,
    /// Where.
    pub at: Loc,
}

/// A set of parts (ids may be character labels).
#[derive(Clone, Debug)]
pub struct PartSetCard {
    /// Members.
    pub ids: Vec<Key>,
    /// Where.
    pub at: Loc,
}

/// A set of segments (four node ids each; a triangle repeats its third node).
#[derive(Clone, Debug)]
pub struct SegmentSetCard {
    /// Segments.
    pub segments: Vec<[i64; 4]>,
    /// Where.
    pub at: Loc,
}

/// What a boundary condition or load acts on.
#[derive(Clone, Debug, PartialEq)]
pub enum Target {
    /// A node.
    Node(i64),
    /// A node set.
    NodeSet(i64),
    /// A rigid part.
    Part(Key),
}

/// `*BOUNDARY_SPC_NODE` / `_SET` (one line).
#[derive(Clone, Debug)]
pub struct SpcCard {
    /// Node or set.
    pub target: Target,
    /// DOFX, DOFY, DOFZ.
    pub dof: [bool; 3],
    /// Where.
    pub at: Loc,
}

/// `*BOUNDARY_PRESCRIBED_MOTION_*` (one line).
#[derive(Clone, Debug)]
pub struct MotionCard {
    /// Node, set or rigid part.
    pub target: Target,
    /// DOF.
    pub dof: i64,
    /// VAD (0 velocity, 1 acceleration, 2 displacement).
    pub vad: i64,
    /// Load curve.
    pub lcid: Key,
    /// Scale factor.
    pub sf: f64,
    /// Vector id (DOF 4, -4).
    pub vid: Option<i64>,
    /// Where.
    pub at: Loc,
}

/// `*LOAD_NODE_POINT` / `_SET` (one line).
#[derive(Clone, Debug)]
pub struct NodeLoadCard {
    /// Node or set.
    pub target: Target,
    /// DOF (1-3).
    pub dof: i64,
    /// Load curve.
    pub lcid: Key,
    /// Scale factor.
    pub sf: f64,
    /// Where.
    pub at: Loc,
}

/// `*LOAD_BODY_X/Y/Z`.
#[derive(Clone, Debug)]
pub struct BodyLoadCard {
    /// Axis (0, 1, 2).
    pub axis: usize,
    /// Load curve.
    pub lcid: Key,
    /// Scale factor.
    pub sf: f64,
    /// Where.
    pub at: Loc,
}

/// `*INITIAL_VELOCITY` / `_NODE`.
#[derive(Clone, Debug)]
pub struct InitVelCard {
    /// Node or node set (`NodeSet(0)`: every node).
    pub target: Target,
    /// Velocity (deck units).
    pub v: [f64; 3],
    /// Where.
    pub at: Loc,
}

/// A `*CONTACT_...` card.
#[derive(Clone, Debug)]
pub struct ContactCard {
    /// The keyword as written.
    pub keyword: String,
    /// Single-surface contact (only SSID).
    pub single: bool,
    /// SSID, MSID.
    pub ids: [i64; 2],
    /// SSTYP, MSTYP.
    pub types: [i64; 2],
    /// Static and dynamic friction, decay.
    pub fs: f64,
    /// FD.
    pub fd: f64,
    /// DC.
    pub dc: f64,
    /// Viscous damping, percent of critical.
    pub vdc: f64,
    /// SFS, SFM.
    pub sf: [f64; 2],
    /// SOFT (optional card A).
    pub soft: i64,
    /// SOFSCL.
    pub sofscl: f64,
    /// Where.
    pub at: Loc,
    /// `$palpa:` comments.
    pub palpa: Vec<(Loc, String)>,
}

/// An output request `*DATABASE_...` with an interval.
#[derive(Clone, Debug)]
pub struct OutputCard {
    /// Which (GLSTAT, RCFORC, SPCFORC, BNDOUT, ELOUT).
    pub what: String,
    /// Interval (deck units).
    pub dt: f64,
    /// Where.
    pub at: Loc,
}

/// `*CONTROL_TIMESTEP`.
#[derive(Clone, Debug)]
pub struct TimestepCard {
    /// TSSFAC.
    pub tssfac: f64,
    /// DT2MS.
    pub dt2ms: f64,
    /// LCTM (largest step against time).
    pub lctm: Option<Key>,
    /// DT2MSF (card 2).
    pub dt2msf: f64,
    /// Where.
    pub at: Loc,
    /// `$palpa:` comments (`target_dt`: the exact mass-scaling step).
    pub palpa: Vec<(Loc, String)>,
}

/// `*CONTROL_TERMINATION`.
#[derive(Clone, Debug)]
pub struct TerminationCard {
    /// ENDTIM.
    pub endtim: f64,
    /// DTMIN (fraction of the initial step).
    pub dtmin: f64,
    /// ENDMAS (percent).
    pub endmas: f64,
    /// Where.
    pub at: Loc,
}

/// `*DATABASE_BINARY_D3PLOT`.
#[derive(Clone, Debug)]
pub struct D3plotCard {
    /// DT (deck units), or 0.
    pub dt: f64,
    /// NPLTC (number of states), or 0.
    pub npltc: i64,
    /// Where.
    pub at: Loc,
    /// `$palpa:` comments.
    pub palpa: Vec<(Loc, String)>,
}

/// Everything palpa reads from a deck, in deck units.
#[derive(Clone, Debug, Default)]
pub struct Deck {
    /// `*TITLE`.
    pub title: Option<String>,
    /// `*CONTROL_UNITS` (LENGTH, TIME, MASS).
    pub control_units: Option<([String; 3], Loc)>,
    /// Nodes.
    pub nodes: Vec<NodeCard>,
    /// Solid elements.
    pub solids: Vec<ElementCard>,
    /// Shell elements.
    pub shells: Vec<ElementCard>,
    /// Parts, in order.
    pub parts: Vec<PartCard>,
    /// Sections.
    pub sections: BTreeMap<Key, SectionCard>,
    /// Materials.
    pub mats: BTreeMap<Key, MatCard>,
    /// Hourglass cards.
    pub hourglass: BTreeMap<Key, HourglassCard>,
    /// `*CONTROL_HOURGLASS` (IHQ, QH).
    pub control_hourglass: Option<(i64, f64, Loc)>,
    /// `*CONTROL_TERMINATION`.
    pub termination: Option<TerminationCard>,
    /// `*CONTROL_TIMESTEP`.
    pub timestep: Option<TimestepCard>,
    /// `*CONTROL_BULK_VISCOSITY` (Q1, Q2).
    pub bulk: Option<(f64, f64, Loc)>,
    /// Its `$palpa:` comments (`bulk_viscosity = false`: off, which LS-DYNA cannot say).
    pub bulk_palpa: Vec<(Loc, String)>,
    /// `*CONTROL_CONTACT` SLSFAC.
    pub slsfac: Option<(f64, Loc)>,
    /// `*DAMPING_GLOBAL` VALDMP.
    pub damping: Option<(f64, Loc)>,
    /// Body loads.
    pub body: Vec<BodyLoadCard>,
    /// Curves.
    pub curves: BTreeMap<Key, CurveCard>,
    /// Vectors (head - tail).
    pub vectors: BTreeMap<i64, ([f64; 3], Loc)>,
    /// Node sets.
    pub node_sets: BTreeMap<i64, SetCard>,
    /// Part sets.
    pub part_sets: BTreeMap<i64, PartSetCard>,
    /// Solid element sets.
    pub solid_sets: BTreeMap<i64, SetCard>,
    /// Segment sets.
    pub segment_sets: BTreeMap<i64, SegmentSetCard>,
    /// SPCs.
    pub spcs: Vec<SpcCard>,
    /// Prescribed motions.
    pub motions: Vec<MotionCard>,
    /// Nodal loads.
    pub node_loads: Vec<NodeLoadCard>,
    /// Initial velocities.
    pub init_vel: Vec<InitVelCard>,
    /// Contacts.
    pub contacts: Vec<ContactCard>,
    /// `*DATABASE_BINARY_D3PLOT`.
    pub d3plot: Option<D3plotCard>,
    /// ASCII output requests with intervals.
    pub outputs: Vec<OutputCard>,
    /// `*DATABASE_HISTORY_SOLID_SET` set ids and `*DATABASE_HISTORY_SOLID` element ids.
    pub history_solid: Vec<(Option<i64>, Vec<i64>, Loc)>,
    /// Keyword counts (for `check`).
    pub counts: BTreeMap<String, usize>,
    /// Warnings (what is ignored and why).
    pub warnings: Vec<String>,
    /// Errors (what palpa cannot run).
    pub errors: Vec<String>,
    /// `$palpa:` comments before the first keyword.
    pub header_palpa: Vec<(Loc, String)>,
    /// `$palpa:` comments of the `*NODE` blocks (exact coordinates of nodes that did not fit).
    pub node_palpa: Vec<(Loc, String)>,
}

/// Cards of a block, read in order.
struct Cards<'a> {
    b: &'a Block,
    i: usize,
}

impl<'a> Cards<'a> {
    fn new(b: &'a Block) -> Self {
        Cards { b, i: 0 }
    }
    /// The next card, blank or not (None when the keyword has no more).
    fn next(&mut self) -> Option<&'a Card> {
        let c = self.b.cards.get(self.i);
        self.i += 1;
        c
    }
    /// The next card cut into `layout` (blank when missing).
    fn fields(&mut self, layout: &'static [Field]) -> Result<Fields, String> {
        let c = self.next();
        fields(self.b, c, layout)
    }
    /// The remaining non-blank cards.
    fn rest(&mut self) -> impl Iterator<Item = &'a Card> {
        let r = &self.b.cards[self.i.min(self.b.cards.len())..];
        self.i = self.b.cards.len();
        r.iter().filter(|c| !c.text.trim().is_empty())
    }
    /// Whether a non-blank card remains.
    fn more(&self) -> bool {
        self.b.cards[self.i.min(self.b.cards.len())..]
            .iter()
            .any(|c| !c.text.trim().is_empty())
    }
    /// The title card (whole line).
    fn title(&mut self) -> String {
        self.next()
            .map(|c| c.text.trim().to_string())
            .unwrap_or_default()
    }
}

// Layouts (standard widths).
const NODE: &[Field] = &[
    ("NID", 8),
    ("X", 16),
    ("Y", 16),
    ("Z", 16),
    ("TC", 8),
    ("RC", 8),
];
const ELEM10: &[Field] = &[
    ("EID", 8),
    ("PID", 8),
    ("N1", 8),
    ("N2", 8),
    ("N3", 8),
    ("N4", 8),
    ("N5", 8),
    ("N6", 8),
    ("N7", 8),
    ("N8", 8),
];
const ELEM_NODES: &[Field] = &[
    ("N1", 8),
    ("N2", 8),
    ("N3", 8),
    ("N4", 8),
    ("N5", 8),
    ("N6", 8),
    ("N7", 8),
    ("N8", 8),
    ("N9", 8),
    ("N10", 8),
];
const PART: &[Field] = &[
    ("PID", 10),
    ("SECID", 10),
    ("MID", 10),
    ("EOSID", 10),
    ("HGID", 10),
    ("GRAV", 10),
    ("ADPOPT", 10),
    ("TMID", 10),
];
const SECTION_SOLID: &[Field] = &[
    ("SECID", 10),
    ("ELFORM", 10),
    ("AET", 10),
    ("UNUSED4", 10),
    ("UNUSED5", 10),
    ("UNUSED6", 10),
    ("COHOFF", 10),
    ("GASKETT", 10),
];
const SECTION_SHELL: &[Field] = &[
    ("SECID", 10),
    ("ELFORM", 10),
    ("SHRF", 10),
    ("NIP", 10),
    ("PROPT", 10),
    ("QR/IRID", 10),
    ("ICOMP", 10),
    ("SETYP", 10),
];
const SECTION_SHELL2: &[Field] = &[
    ("T1", 10),
    ("T2", 10),
    ("T3", 10),
    ("T4", 10),
    ("NLOC", 10),
    ("MAREA", 10),
    ("IDOF", 10),
    ("EDGSET", 10),
];
const MAT001: &[Field] = &[
    ("MID", 10),
    ("RO", 10),
    ("E", 10),
    ("PR", 10),
    ("DA", 10),
    ("DB", 10),
    ("K", 10),
    ("UNUSED", 10),
];
const MAT077: &[Field] = &[
    ("MID", 10),
    ("RO", 10),
    ("PR", 10),
    ("N", 10),
    ("NV", 10),
    ("G", 10),
    ("SIGF", 10),
    ("REF", 10),
];
const MU8: &[Field] = &[
    ("MU1", 10),
    ("MU2", 10),
    ("MU3", 10),
    ("MU4", 10),
    ("MU5", 10),
    ("MU6", 10),
    ("MU7", 10),
    ("MU8", 10),
];
const ALPHA8: &[Field] = &[
    ("ALPHA1", 10),
    ("ALPHA2", 10),
    ("ALPHA3", 10),
    ("ALPHA4", 10),
    ("ALPHA5", 10),
    ("ALPHA6", 10),
    ("ALPHA7", 10),
    ("ALPHA8", 10),
];
const PRONY: &[Field] = &[
    ("GI", 10),
    ("BETAI", 10),
    ("UNUSED3", 10),
    ("UNUSED4", 10),
    ("UNUSED5", 10),
    ("UNUSED6", 10),
    ("UNUSED7", 10),
    ("UNUSED8", 10),
];
const MAT181: &[Field] = &[
    ("MID", 10),
    ("RO", 10),
    ("KM", 10),
    ("MU", 10),
    ("G", 10),
    ("SIGF", 10),
    ("REF", 10),
    ("PRTEN", 10),
];
const MAT181_2: &[Field] = &[
    ("SGL", 10),
    ("SW", 10),
    ("ST", 10),
    ("LC/TBID", 10),
    ("TENSION", 10),
    ("RTYPE", 10),
    ("AVGOPT", 10),
    ("PR/BETA", 10),
];
const MAT181_3: &[Field] = &[
    ("LCUNLD", 10),
    ("HU", 10),
    ("SHAPE", 10),
    ("STOL", 10),
    ("VISCO", 10),
    ("HISOUT", 10),
    ("UNUSED7", 10),
    ("UNUSED8", 10),
];
const MAT024: &[Field] = &[
    ("MID", 10),
    ("RO", 10),
    ("E", 10),
    ("PR", 10),
    ("SIGY", 10),
    ("ETAN", 10),
    ("FAIL", 10),
    ("TDEL", 10),
];
const MAT024_2: &[Field] = &[
    ("C", 10),
    ("P", 10),
    ("LCSS", 10),
    ("LCSR", 10),
    ("VP", 10),
    ("LCF", 10),
    ("UNUSED7", 10),
    ("UNUSED8", 10),
];
const EPS8: &[Field] = &[
    ("EPS1", 10),
    ("EPS2", 10),
    ("EPS3", 10),
    ("EPS4", 10),
    ("EPS5", 10),
    ("EPS6", 10),
    ("EPS7", 10),
    ("EPS8", 10),
];
const ES8: &[Field] = &[
    ("ES1", 10),
    ("ES2", 10),
    ("ES3", 10),
    ("ES4", 10),
    ("ES5", 10),
    ("ES6", 10),
    ("ES7", 10),
    ("ES8", 10),
];
const MAT020: &[Field] = &[
    ("MID", 10),
    ("RO", 10),
    ("E", 10),
    ("PR", 10),
    ("N", 10),
    ("COUPLE", 10),
    ("M", 10),
    ("ALIAS", 10),
];
const MAT020_2: &[Field] = &[
    ("CMO", 10),
    ("CON1", 10),
    ("CON2", 10),
    ("UNUSED4", 10),
    ("UNUSED5", 10),
    ("UNUSED6", 10),
    ("UNUSED7", 10),
    ("UNUSED8", 10),
];
const HOURGLASS: &[Field] = &[
    ("HGID", 10),
    ("IHQ", 10),
    ("QM", 10),
    ("IBQ", 10),
    ("Q1", 10),
    ("Q2", 10),
    ("QB/VDC", 10),
    ("QW", 10),
];
const CONTROL_HOURGLASS: &[Field] = &[
    ("IHQ", 10),
    ("QH", 10),
    ("UNUSED3", 10),
    ("UNUSED4", 10),
    ("UNUSED5", 10),
    ("UNUSED6", 10),
    ("UNUSED7", 10),
    ("UNUSED8", 10),
];
const TERMINATION: &[Field] = &[
    ("ENDTIM", 10),
    ("ENDCYC", 10),
    ("DTMIN", 10),
    ("ENDENG", 10),
    ("ENDMAS", 10),
    ("NOSOL", 10),
    ("UNUSED7", 10),
    ("UNUSED8", 10),
];
const TIMESTEP: &[Field] = &[
    ("DTINIT", 10),
    ("TSSFAC", 10),
    ("ISDO", 10),
    ("TSLIMT", 10),
    ("DT2MS", 10),
    ("LCTM", 10),
    ("ERODE", 10),
    ("MS1ST", 10),
];
const TIMESTEP2: &[Field] = &[
    ("DT2MSF", 10),
    ("DT2MSLC", 10),
    ("IMSCL", 10),
    ("UNUSED4", 10),
    ("UNUSED5", 10),
    ("RMSCL", 10),
    ("UNUSED7", 10),
    ("IHDO", 10),
];
const BULK: &[Field] = &[
    ("Q1", 10),
    ("Q2", 10),
    ("TYPE", 10),
    ("BTYPE", 10),
    ("TSTYPE", 10),
    ("UNUSED6", 10),
    ("UNUSED7", 10),
    ("UNUSED8", 10),
];
const UNITS: &[Field] = &[
    ("LENGTH", 10),
    ("TIME", 10),
    ("MASS", 10),
    ("TEMP", 10),
    ("UNUSED5", 10),
    ("UNUSED6", 10),
    ("UNUSED7", 10),
    ("UNUSED8", 10),
];
const CONTROL_CONTACT: &[Field] = &[
    ("SLSFAC", 10),
    ("RWPNAL", 10),
    ("ISLCHK", 10),
    ("SHLTHK", 10),
    ("PENOPT", 10),
    ("THKCHG", 10),
    ("ORIEN", 10),
    ("ENMASS", 10),
];
const DAMPING_GLOBAL: &[Field] = &[
    ("LCID", 10),
    ("VALDMP", 10),
    ("STX", 10),
    ("STY", 10),
    ("STZ", 10),
    ("SRX", 10),
    ("SRY", 10),
    ("SRZ", 10),
];
const LOAD_BODY: &[Field] = &[
    ("LCID", 10),
    ("SF", 10),
    ("LCIDDR", 10),
    ("XC", 10),
    ("YC", 10),
    ("ZC", 10),
    ("CID", 10),
    ("UNUSED8", 10),
];
const CURVE: &[Field] = &[
    ("LCID", 10),
    ("SIDR", 10),
    ("SFA", 10),
    ("SFO", 10),
    ("OFFA", 10),
    ("OFFO", 10),
    ("DATTYP", 10),
    ("LCINT", 10),
];
const POINT: &[Field] = &[("A", 20), ("O", 20)];
const VECTOR: &[Field] = &[
    ("VID", 10),
    ("XT", 10),
    ("YT", 10),
    ("ZT", 10),
    ("XH", 10),
    ("YH", 10),
    ("ZH", 10),
    ("CID", 10),
];
const SET_HEAD: &[Field] = &[
    ("SID", 10),
    ("DA1", 10),
    ("DA2", 10),
    ("DA3", 10),
    ("DA4", 10),
    ("SOLVER", 10),
    ("UNUSED7", 10),
    ("UNUSED8", 10),
];
const SET_SOLID_HEAD: &[Field] = &[
    ("SID", 10),
    ("SOLVER", 10),
    ("UNUSED3", 10),
    ("UNUSED4", 10),
    ("UNUSED5", 10),
    ("UNUSED6", 10),
    ("UNUSED7", 10),
    ("UNUSED8", 10),
];
const IDS8: &[Field] = &[
    ("ID1", 10),
    ("ID2", 10),
    ("ID3", 10),
    ("ID4", 10),
    ("ID5", 10),
    ("ID6", 10),
    ("ID7", 10),
    ("ID8", 10),
];
const SEGMENT: &[Field] = &[
    ("N1", 10),
    ("N2", 10),
    ("N3", 10),
    ("N4", 10),
    ("A1", 10),
    ("A2", 10),
    ("A3", 10),
    ("A4", 10),
];
const SPC: &[Field] = &[
    ("ID", 10),
    ("CID", 10),
    ("DOFX", 10),
    ("DOFY", 10),
    ("DOFZ", 10),
    ("DOFRX", 10),
    ("DOFRY", 10),
    ("DOFRZ", 10),
];
const MOTION: &[Field] = &[
    ("ID", 10),
    ("DOF", 10),
    ("VAD", 10),
    ("LCID", 10),
    ("SF", 10),
    ("VID", 10),
    ("DEATH", 10),
    ("BIRTH", 10),
];
const LOAD_NODE: &[Field] = &[
    ("ID", 10),
    ("DOF", 10),
    ("LCID", 10),
    ("SF", 10),
    ("CID", 10),
    ("M1", 10),
    ("M2", 10),
    ("M3", 10),
];
const INIT_VEL: &[Field] = &[
    ("NSID", 10),
    ("NSIDEX", 10),
    ("BOXID", 10),
    ("IRIGID", 10),
    ("ICID", 10),
    ("UNUSED6", 10),
    ("UNUSED7", 10),
    ("UNUSED8", 10),
];
const INIT_VEL2: &[Field] = &[
    ("VX", 10),
    ("VY", 10),
    ("VZ", 10),
    ("VXR", 10),
    ("VYR", 10),
    ("VZR", 10),
    ("UNUSED7", 10),
    ("UNUSED8", 10),
];
const INIT_VEL_NODE: &[Field] = &[
    ("NID", 10),
    ("VX", 10),
    ("VY", 10),
    ("VZ", 10),
    ("VXR", 10),
    ("VYR", 10),
    ("VZR", 10),
    ("ICID", 10),
];
const CONTACT1: &[Field] = &[
    ("SSID", 10),
    ("MSID", 10),
    ("SSTYP", 10),
    ("MSTYP", 10),
    ("SBOXID", 10),
    ("MBOXID", 10),
    ("SPR", 10),
    ("MPR", 10),
];
const CONTACT2: &[Field] = &[
    ("FS", 10),
    ("FD", 10),
    ("DC", 10),
    ("VC", 10),
    ("VDC", 10),
    ("PENCHK", 10),
    ("BT", 10),
    ("DT", 10),
];
const CONTACT3: &[Field] = &[
    ("SFS", 10),
    ("SFM", 10),
    ("SST", 10),
    ("MST", 10),
    ("SFST", 10),
    ("SFMT", 10),
    ("FSF", 10),
    ("VSF", 10),
];
const CONTACT_A: &[Field] = &[
    ("SOFT", 10),
    ("SOFSCL", 10),
    ("LCIDAB", 10),
    ("MAXPAR", 10),
    ("SBOPT", 10),
    ("DEPTH", 10),
    ("BSORT", 10),
    ("FRCFRQ", 10),
];
const D3PLOT: &[Field] = &[
    ("DT", 10),
    ("LCDT", 10),
    ("BEAM", 10),
    ("NPLTC", 10),
    ("PSETID", 10),
    ("UNUSED6", 10),
    ("UNUSED7", 10),
    ("UNUSED8", 10),
];
const ASCII_OUT: &[Field] = &[
    ("DT", 10),
    ("BINARY", 10),
    ("LCUR", 10),
    ("IOOPT", 10),
    ("DTHF", 10),
    ("BINHF", 10),
    ("UNUSED7", 10),
    ("UNUSED8", 10),
];

/// Keywords that only ask for output or tune LS-DYNA's bookkeeping: read past with a warning.
const OUTPUT_ONLY: &[&str] = &[
    "DATABASE_",
    "CONTROL_OUTPUT",
    "CONTROL_ENERGY",
    "CONTROL_CPU",
    "CONTROL_PARALLEL",
    "CONTROL_MPP",
    "CONTROL_DEBUG",
    "CONTROL_STRUCTURED",
    "CONTROL_REPORT",
    "CONTROL_ACCURACY",
    "CONTROL_SOLID",
    "CONTROL_SHELL",
    "CONTROL_RIGID",
    "COMMENT",
    "TITLE",
    "DEFINE_CURVE_TITLE",
];

/// Explanations for keywords users often bring that palpa does not run.
fn unsupported_hint(name: &str) -> &'static str {
    let h: &[(&str, &str)] = &[
        ("CONSTRAINED_", "palpa has no constraints between parts or nodes: merge the nodes, or make the parts one part"),
        ("ELEMENT_BEAM", "palpa has 8-node solid elements only"),
        ("ELEMENT_SHELL", "shells are read only as the surface of rigid (*MAT_RIGID) parts"),
        ("ELEMENT_DISCRETE", "palpa has 8-node solid elements only"),
        ("ELEMENT_MASS", "palpa has no lumped masses besides the elements'"),
        ("CONTROL_IMPLICIT", "palpa is an explicit solver; remove the implicit controls"),
        ("CONTROL_DYNAMIC_RELAXATION", "palpa's dynamic relaxation is a scene option ([relaxation]), not LS-DYNA's"),
        ("RIGIDWALL", "model the wall as a rigid (*MAT_RIGID) part in *CONTACT"),
        ("INITIAL_STRESS", "palpa starts from the stress-free reference state"),
        ("PARAMETER_EXPRESSION", "palpa expands *PARAMETER but does not evaluate expressions: give the values"),
        ("PARAMETER_", "palpa reads plain *PARAMETER (and *PARAMETER_LOCAL)"),
        ("DEFINE_TABLE", "only *DEFINE_CURVE is read"),
        ("DEFINE_TRANSFORMATION", "transform the nodes before reading the deck"),
        ("INCLUDE_TRANSFORM", "transform the nodes before reading the deck"),
        ("EOS_", "palpa's laws carry their own volumetric response"),
        ("MAT_", "palpa reads *MAT_ELASTIC, *MAT_OGDEN_RUBBER, *MAT_SIMPLIFIED_RUBBER/FOAM, *MAT_PIECEWISE_LINEAR_PLASTICITY and *MAT_RIGID"),
        ("SECTION_", "palpa reads *SECTION_SOLID (and *SECTION_SHELL for rigid parts)"),
        ("CONTACT_", "palpa reads *CONTACT_AUTOMATIC_SURFACE_TO_SURFACE, *CONTACT_SURFACE_TO_SURFACE and *CONTACT_AUTOMATIC_SINGLE_SURFACE between deformable and rigid parts"),
        ("BOUNDARY_", "palpa reads *BOUNDARY_SPC_NODE/_SET and *BOUNDARY_PRESCRIBED_MOTION_NODE/_SET/_RIGID"),
        ("LOAD_", "palpa reads *LOAD_NODE_POINT/_SET and *LOAD_BODY_X/Y/Z"),
        ("PART_", "palpa reads plain *PART"),
    ];
    h.iter()
        .find(|(p, _)| name.starts_with(p))
        .map(|(_, t)| *t)
        .unwrap_or("see docs/lsdyna.md for the keywords palpa reads")
}

/// Strip an option suffix; returns the base and whether it was there.
fn strip<'s>(name: &'s str, suffix: &str) -> (&'s str, bool) {
    match name.strip_suffix(suffix) {
        Some(b) => (b, true),
        None => (name, false),
    }
}

/// Parse every block.
pub fn parse(lexed: &Lexed) -> Deck {
    let mut d = Deck {
        header_palpa: lexed.header_palpa.clone(),
        ..Default::default()
    };
    for b in &lexed.blocks {
        *d.counts.entry(b.name.clone()).or_default() += 1;
        if let Err(e) = parse_block(&mut d, b) {
            d.errors.push(e);
        }
    }
    d
}

fn warn_fields(d: &mut Deck, f: &Fields, names: &[&str], why: &str) {
    for (n, v) in f.given(names) {
        if v.parse::<f64>().map(|x| x == 0.0).unwrap_or(false) {
            continue;
        }
        d.warnings
            .push(format!("{}: `{v}` ignored: {why}", f.at(&n)));
    }
}

fn parse_block(d: &mut Deck, b: &Block) -> Result<(), String> {
    let name = b.name.as_str();
    let mut c = Cards::new(b);
    let kw = format!("*{name}");
    match name {
        "TITLE" => {
            d.title = Some(c.title());
        }
        // Read by the lexer (crate::params): its values replace `&NAME` in later cards.
        "PARAMETER" | "PARAMETER_LOCAL" => {}
        "NODE" => {
            d.node_palpa.extend(b.palpa.iter().cloned());
            for card in c.rest() {
                let f = fields(b, Some(card), NODE)?;
                d.nodes.push(NodeCard {
                    id: f.int_req("NID")?,
                    x: [f.real("X", 0.0)?, f.real("Y", 0.0)?, f.real("Z", 0.0)?],
                    text: [f.raw("X").into(), f.raw("Y").into(), f.raw("Z").into()],
                    tc: f.int("TC", 0)?,
                    at: card.at.clone(),
                });
            }
        }
        "ELEMENT_SOLID" | "ELEMENT_SHELL" => {
            let solid = name == "ELEMENT_SOLID";
            let cards: Vec<&Card> = c.rest().collect();
            let mut i = 0;
            while i < cards.len() {
                let f = fields(b, Some(cards[i]), ELEM10)?;
                let id = f.int_req("EID")?;
                let part = key(f.raw("PID"));
                if part.is_empty() {
                    return Err(f.err("PID", "a part id is required"));
                }
                let mut nodes: Vec<i64> = Vec::new();
                let at = cards[i].at.clone();
                if solid && f.blank("N1") {
                    // Two-card format: EID PID, then N1..N10.
                    let g = fields(b, cards.get(i + 1).copied(), ELEM_NODES)?;
                    for n in ["N1", "N2", "N3", "N4", "N5", "N6", "N7", "N8"] {
                        nodes.push(g.int(n, 0)?);
                    }
                    if g.int("N9", 0)? != 0 || g.int("N10", 0)? != 0 {
                        return Err(g.err(
                            "N9",
                            format!("element {id} has more than 8 nodes; palpa has 8-node hexahedra only"),
                        ));
                    }
                    i += 2;
                } else {
                    let names: &[&str] = if solid {
                        &["N1", "N2", "N3", "N4", "N5", "N6", "N7", "N8"]
                    } else {
                        &["N1", "N2", "N3", "N4"]
                    };
                    for n in names {
                        nodes.push(f.int(n, 0)?);
                    }
                    if !solid && (f.int("N5", 0)? != 0) {
                        return Err(f.err(
                            "N5",
                            format!("shell {id} has more than 4 nodes; rigid surfaces are read as 3- and 4-node shells"),
                        ));
                    }
                    i += 1;
                }
                if let Some(k) = nodes.iter().position(|&n| n <= 0) {
                    return Err(format!(
                        "{at}: {kw} {id}: node N{} is missing ({}); a solid needs 8 nodes, a shell 3 or 4",
                        k + 1,
                        nodes[k]
                    ));
                }
                let e = ElementCard {
                    id,
                    part,
                    nodes,
                    at,
                };
                if solid {
                    d.solids.push(e);
                } else {
                    d.shells.push(e);
                }
            }
        }
        "PART" => {
            let title = c.title();
            let f = c.fields(PART)?;
            if f.int("EOSID", 0)? != 0 {
                return Err(f.err("EOSID", "an equation of state is not supported: palpa's laws carry their own volumetric response"));
            }
            if f.int("TMID", 0)? != 0 {
                return Err(f.err("TMID", "thermal materials are not supported"));
            }
            warn_fields(
                d,
                &f,
                &["GRAV", "ADPOPT"],
                "palpa has no per-part gravity switch or adaptivity",
            );
            let id = key(f.raw("PID"));
            if id.is_empty() {
                return Err(f.err("PID", "a part id is required"));
            }
            d.parts.push(PartCard {
                id,
                title,
                section: key(f.raw("SECID")),
                material: key(f.raw("MID")),
                hourglass: key(f.raw("HGID")),
                at: b.at.clone(),
                palpa: b.palpa.clone(),
            });
        }
        _ if name.starts_with("SECTION_SOLID") || name.starts_with("SECTION_SHELL") => {
            let (base, titled) = strip(name, "_TITLE");
            if base != "SECTION_SOLID" && base != "SECTION_SHELL" {
                return Err(format!(
                    "{}: {kw}: option not supported; {}",
                    b.at,
                    unsupported_hint("SECTION_")
                ));
            }
            if titled {
                c.title();
            }
            let shell = base == "SECTION_SHELL";
            let f = c.fields(if shell { SECTION_SHELL } else { SECTION_SOLID })?;
            let id = key(f.raw("SECID"));
            let elform = f.int("ELFORM", if shell { 2 } else { 1 })?;
            let thickness = if shell {
                c.fields(SECTION_SHELL2)?.real("T1", 0.0)?
            } else {
                if f.real("AET", 0.0)? != 0.0 {
                    return Err(f.err("AET", "ambient element types are not supported"));
                }
                0.0
            };
            d.sections.insert(
                id,
                SectionCard {
                    elform,
                    shell,
                    thickness,
                    at: b.at.clone(),
                    palpa: b.palpa.clone(),
                },
            );
        }
        _ if name.starts_with("MAT_") => parse_mat(d, b)?,
        _ if name.starts_with("HOURGLASS") => {
            let (base, titled) = strip(name, "_TITLE");
            if base != "HOURGLASS" {
                return Err(format!("{}: {kw}: unknown option", b.at));
            }
            if titled {
                c.title();
            }
            let f = c.fields(HOURGLASS)?;
            d.hourglass.insert(
                key(f.raw("HGID")),
                HourglassCard {
                    ihq: f.int("IHQ", 0)?,
                    qm: f.real_opt("QM")?,
                    q1q2: (f.real_opt("Q1")?, f.real_opt("Q2")?),
                    at: b.at.clone(),
                    palpa: b.palpa.clone(),
                },
            );
        }
        "CONTROL_HOURGLASS" => {
            let f = c.fields(CONTROL_HOURGLASS)?;
            d.control_hourglass = Some((
                f.int("IHQ", 1)?,
                nonzero_or(f.real("QH", 0.1)?, 0.1),
                b.at.clone(),
            ));
        }
        "CONTROL_TERMINATION" => {
            let f = c.fields(TERMINATION)?;
            if f.int("ENDCYC", 0)? != 0 {
                d.warnings.push(format!(
                    "{}: ignored: palpa ends the run at ENDTIM only",
                    f.at("ENDCYC")
                ));
            }
            warn_fields(
                d,
                &f,
                &["ENDENG"],
                "palpa reports the energy balance but does not stop on it",
            );
            d.termination = Some(TerminationCard {
                endtim: f.real("ENDTIM", 0.0)?,
                dtmin: f.real("DTMIN", 0.0)?,
                endmas: f.real("ENDMAS", 0.0)?,
                at: b.at.clone(),
            });
        }
        "CONTROL_TIMESTEP" => {
            let f = c.fields(TIMESTEP)?;
            if f.int("MS1ST", 0)? != 0 {
                return Err(f.err("MS1ST", "mass scaling limited to the first step is not supported (palpa adds mass also when an element shrinks during the run)"));
            }
            warn_fields(
                d,
                &f,
                &["DTINIT", "ISDO", "TSLIMT", "ERODE"],
                "palpa computes its own steps (shell and erosion options do not apply)",
            );
            let g = c.fields(TIMESTEP2)?;
            if g.int("DT2MSLC", 0)? != 0 {
                return Err(g.err(
                    "DT2MSLC",
                    "a mass-scaling step that varies in time is not supported",
                ));
            }
            if g.int("IMSCL", 0)? != 0 {
                return Err(g.err("IMSCL", "selective mass scaling (the non-diagonal mass matrix) is not supported; palpa adds lumped mass to small elements (DT2MS < 0)"));
            }
            d.timestep = Some(TimestepCard {
                tssfac: nonzero_or(f.real("TSSFAC", 0.9)?, 0.9),
                dt2ms: f.real("DT2MS", 0.0)?,
                lctm: match f.int("LCTM", 0)? {
                    0 => None,
                    k => Some(k.to_string()),
                },
                dt2msf: g.real("DT2MSF", 0.0)?,
                at: b.at.clone(),
                palpa: b.palpa.clone(),
            });
        }
        "CONTROL_BULK_VISCOSITY" => {
            let f = c.fields(BULK)?;
            let ty = f.int("TYPE", 1)?;
            if ![1, -1, -2].contains(&ty) {
                return Err(f.err(
                    "TYPE",
                    format!(
                        "bulk viscosity type {ty} is not supported (palpa has the standard type 1)"
                    ),
                ));
            }
            // Zero is LS-DYNA's default (1.5, 0.06), not "off".
            d.bulk = Some((
                nonzero_or(f.real("Q1", 1.5)?, 1.5),
                nonzero_or(f.real("Q2", 0.06)?, 0.06),
                b.at.clone(),
            ));
            d.bulk_palpa = b.palpa.clone();
        }
        "CONTROL_UNITS" => {
            let f = c.fields(UNITS)?;
            d.control_units = Some((
                [f.text("LENGTH"), f.text("TIME"), f.text("MASS")],
                b.at.clone(),
            ));
            if c.more() {
                let f2 =
                    c.fields(&[("LENGTH_SCALE", 20), ("TIME_SCALE", 20), ("MASS_SCALE", 20)])?;
                if !f2
                    .given(&["LENGTH_SCALE", "TIME_SCALE", "MASS_SCALE"])
                    .is_empty()
                {
                    return Err(f2.err(
                        "LENGTH_SCALE",
                        "user-defined unit scales are not supported; name the units in card 1",
                    ));
                }
            }
        }
        "CONTROL_CONTACT" => {
            let f = c.fields(CONTROL_CONTACT)?;
            d.slsfac = Some((nonzero_or(f.real("SLSFAC", 0.1)?, 0.1), b.at.clone()));
            warn_fields(
                d,
                &f,
                &[
                    "RWPNAL", "ISLCHK", "SHLTHK", "PENOPT", "THKCHG", "ORIEN", "ENMASS",
                ],
                "palpa's contact has its own search and penalty (see docs/lsdyna.md)",
            );
            if c.more() {
                d.warnings.push(format!(
                    "{}: *CONTROL_CONTACT: cards after the first ignored (LS-DYNA's contact options)",
                    b.at
                ));
            }
        }
        "DAMPING_GLOBAL" => {
            let f = c.fields(DAMPING_GLOBAL)?;
            if f.int("LCID", 0)? != 0 {
                return Err(f.err(
                    "LCID",
                    "damping that varies in time is not supported; give VALDMP",
                ));
            }
            for n in ["STX", "STY", "STZ", "SRX", "SRY", "SRZ"] {
                f.must_be(n, 0.0, "palpa's damping is the same in every direction")?;
            }
            d.damping = Some((f.real("VALDMP", 0.0)?, b.at.clone()));
        }
        "LOAD_BODY_X" | "LOAD_BODY_Y" | "LOAD_BODY_Z" => {
            let f = c.fields(LOAD_BODY)?;
            if f.int("CID", 0)? != 0 {
                return Err(f.err("CID", "local coordinate systems are not supported"));
            }
            if f.int("LCIDDR", 0)? != 0 {
                return Err(f.err("LCIDDR", "a dynamic-relaxation load curve is not supported"));
            }
            d.body.push(BodyLoadCard {
                axis: match name {
                    "LOAD_BODY_X" => 0,
                    "LOAD_BODY_Y" => 1,
                    _ => 2,
                },
                lcid: key(f.raw("LCID")),
                sf: nonzero_or_one(f.real("SF", 1.0)?),
                at: b.at.clone(),
            });
        }
        _ if name.starts_with("DEFINE_CURVE") => {
            let (base, titled) = strip(name, "_TITLE");
            if base != "DEFINE_CURVE" {
                return Err(format!(
                    "{}: {kw} is not supported; only *DEFINE_CURVE is read",
                    b.at
                ));
            }
            let title = titled.then(|| c.title());
            let f = c.fields(CURVE)?;
            let dattyp = f.int("DATTYP", 0)?;
            if dattyp != 0 && dattyp != -100 {
                return Err(f.err(
                    "DATTYP",
                    format!("curve data type {dattyp} is not supported (0: a plain curve)"),
                ));
            }
            let sidr = f.int("SIDR", 0)?;
            let mut points = Vec::new();
            for card in c.rest() {
                let p = fields(b, Some(card), POINT)?;
                points.push((p.real("A", 0.0)?, p.real("O", 0.0)?));
            }
            let id = key(f.raw("LCID"));
            if points.is_empty() {
                return Err(format!("{}: {kw} {id} has no points", b.at));
            }
            if let Some(w) = points.windows(2).position(|w| w[1].0 < w[0].0) {
                return Err(format!(
                    "{}: {kw} {id}: abscissa values must not decrease (point {} after point {})",
                    b.at,
                    w + 2,
                    w + 1
                ));
            }
            d.curves.insert(
                id,
                CurveCard {
                    sidr,
                    sfa: nonzero_or_one(f.real("SFA", 1.0)?),
                    sfo: nonzero_or_one(f.real("SFO", 1.0)?),
                    offa: f.real("OFFA", 0.0)?,
                    offo: f.real("OFFO", 0.0)?,
                    points,
                    title,
                    at: b.at.clone(),
                    palpa: b.palpa.clone(),
                },
            );
        }
        _ if name.starts_with("DEFINE_VECTOR") => {
            let (base, titled) = strip(name, "_TITLE");
            if base != "DEFINE_VECTOR" {
                return Err(format!("{}: {kw} is not supported", b.at));
            }
            if titled {
                c.title();
            }
            let f = c.fields(VECTOR)?;
            if f.int("CID", 0)? != 0 {
                return Err(f.err("CID", "local coordinate systems are not supported"));
            }
            let v = [
                f.real("XH", 0.0)? - f.real("XT", 0.0)?,
                f.real("YH", 0.0)? - f.real("YT", 0.0)?,
                f.real("ZH", 0.0)? - f.real("ZT", 0.0)?,
            ];
            d.vectors.insert(f.int_req("VID")?, (v, b.at.clone()));
        }
        _ if name.starts_with("SET_") => parse_set(d, b)?,
        _ if name.starts_with("BOUNDARY_SPC") => {
            let base = name.trim_end_matches("_ID");
            let with_id = base.len() != name.len();
            let set = match base {
                "BOUNDARY_SPC_NODE" => false,
                "BOUNDARY_SPC_SET" => true,
                _ => {
                    return Err(format!(
                        "{}: {kw} is not supported; palpa reads *BOUNDARY_SPC_NODE and *BOUNDARY_SPC_SET (without birth and death times)",
                        b.at
                    ))
                }
            };
            if with_id {
                c.next();
            }
            for card in c.rest() {
                let f = fields(b, Some(card), SPC)?;
                if f.int("CID", 0)? != 0 {
                    return Err(f.err("CID", "local coordinate systems are not supported"));
                }
                let id = f.int_req("ID")?;
                d.spcs.push(SpcCard {
                    target: if set {
                        Target::NodeSet(id)
                    } else {
                        Target::Node(id)
                    },
                    dof: [
                        f.int("DOFX", 0)? != 0,
                        f.int("DOFY", 0)? != 0,
                        f.int("DOFZ", 0)? != 0,
                    ],
                    at: card.at.clone(),
                });
            }
        }
        _ if name.starts_with("BOUNDARY_PRESCRIBED_MOTION") => {
            let base = name.trim_end_matches("_ID");
            let with_id = base.len() != name.len();
            let kind = match base {
                "BOUNDARY_PRESCRIBED_MOTION_NODE" => 0,
                "BOUNDARY_PRESCRIBED_MOTION_SET" => 1,
                "BOUNDARY_PRESCRIBED_MOTION_RIGID" => 2,
                _ => {
                    return Err(format!(
                        "{}: {kw} is not supported; palpa reads *BOUNDARY_PRESCRIBED_MOTION_NODE, _SET and _RIGID (with _ID)",
                        b.at
                    ))
                }
            };
            let cards: Vec<&Card> = c.rest().collect();
            let mut i = 0;
            while i < cards.len() {
                if with_id {
                    i += 1;
                }
                let Some(card) = cards.get(i) else { break };
                i += 1;
                let f = fields(b, Some(card), MOTION)?;
                let death = f.real("DEATH", 0.0)?;
                if death != 0.0 && death < 1e20 {
                    return Err(f.err(
                        "DEATH",
                        "a motion that ends before the run does is not supported",
                    ));
                }
                f.must_be("BIRTH", 0.0, "a motion starts at t = 0 in palpa")?;
                let dof = f.int_req("DOF")?;
                if kind < 2 && (9..=11).contains(&dof.abs()) {
                    return Err(f.err(
                        "DOF",
                        "rotations about an axis (DOF 9-11) are not supported",
                    ));
                }
                let id = f.raw("ID").to_string();
                if id.is_empty() {
                    return Err(f.err("ID", "an id is required"));
                }
                d.motions.push(MotionCard {
                    target: match kind {
                        0 => Target::Node(f.int_req("ID")?),
                        1 => Target::NodeSet(f.int_req("ID")?),
                        _ => Target::Part(key(&id)),
                    },
                    dof,
                    vad: f.int("VAD", 0)?,
                    lcid: key(f.raw("LCID")),
                    sf: nonzero_or_one(f.real("SF", 1.0)?),
                    vid: f.int_opt("VID")?.filter(|&v| v != 0),
                    at: card.at.clone(),
                });
            }
        }
        "LOAD_NODE_POINT" | "LOAD_NODE_SET" => {
            for card in c.rest() {
                let f = fields(b, Some(card), LOAD_NODE)?;
                if f.int("CID", 0)? != 0 {
                    return Err(f.err("CID", "local coordinate systems are not supported"));
                }
                let id = f.int_req("ID")?;
                d.node_loads.push(NodeLoadCard {
                    target: if name == "LOAD_NODE_SET" {
                        Target::NodeSet(id)
                    } else {
                        Target::Node(id)
                    },
                    dof: f.int_req("DOF")?,
                    lcid: key(f.raw("LCID")),
                    sf: nonzero_or_one(f.real("SF", 1.0)?),
                    at: card.at.clone(),
                });
            }
        }
        "INITIAL_VELOCITY" => {
            let f = c.fields(INIT_VEL)?;
            for n in ["NSIDEX", "BOXID", "ICID"] {
                if f.int(n, 0)? != 0 {
                    return Err(f.err(
                        n,
                        "exempted sets, boxes and local systems are not supported",
                    ));
                }
            }
            let g = c.fields(INIT_VEL2)?;
            d.init_vel.push(InitVelCard {
                target: Target::NodeSet(f.int("NSID", 0)?),
                v: [g.real("VX", 0.0)?, g.real("VY", 0.0)?, g.real("VZ", 0.0)?],
                at: b.at.clone(),
            });
        }
        "INITIAL_VELOCITY_NODE" => {
            for card in c.rest() {
                let f = fields(b, Some(card), INIT_VEL_NODE)?;
                if f.int("ICID", 0)? != 0 {
                    return Err(f.err("ICID", "local coordinate systems are not supported"));
                }
                d.init_vel.push(InitVelCard {
                    target: Target::Node(f.int_req("NID")?),
                    v: [f.real("VX", 0.0)?, f.real("VY", 0.0)?, f.real("VZ", 0.0)?],
                    at: card.at.clone(),
                });
            }
        }
        _ if name.starts_with("CONTACT_") => parse_contact(d, b)?,
        "DATABASE_BINARY_D3PLOT" => {
            let f = c.fields(D3PLOT)?;
            if f.int("LCDT", 0)? != 0 {
                return Err(f.err(
                    "LCDT",
                    "an output interval that varies in time is not supported; give DT",
                ));
            }
            warn_fields(d, &f, &["BEAM", "PSETID"], "palpa writes every part");
            d.d3plot = Some(D3plotCard {
                dt: f.real("DT", 0.0)?,
                npltc: f.int("NPLTC", 0)?,
                at: b.at.clone(),
                palpa: b.palpa.clone(),
            });
        }
        "DATABASE_GLSTAT" | "DATABASE_RCFORC" | "DATABASE_SPCFORC" | "DATABASE_BNDOUT"
        | "DATABASE_ELOUT" => {
            let f = c.fields(ASCII_OUT)?;
            let dt = f.real("DT", 0.0)?;
            if !(dt > 0.0) {
                return Err(f.err("DT", "the output interval must be positive"));
            }
            d.outputs.push(OutputCard {
                what: name["DATABASE_".len()..].to_string(),
                dt,
                at: b.at.clone(),
            });
        }
        "DATABASE_HISTORY_SOLID" | "DATABASE_HISTORY_SOLID_SET" | "DATABASE_HISTORY_SOLID_ID" => {
            let mut ids = Vec::new();
            for card in c.rest() {
                let f = fields(b, Some(card), IDS8)?;
                for k in ["ID1", "ID2", "ID3", "ID4", "ID5", "ID6", "ID7", "ID8"] {
                    if let Some(v) = f.int_opt(k)?.filter(|&v| v != 0) {
                        ids.push(v);
                    }
                }
            }
            if name == "DATABASE_HISTORY_SOLID_SET" {
                for s in ids {
                    d.history_solid.push((Some(s), Vec::new(), b.at.clone()));
                }
            } else {
                d.history_solid.push((None, ids, b.at.clone()));
            }
        }
        _ => {
            if OUTPUT_ONLY.iter().any(|p| name.starts_with(p)) {
                let why = if name.starts_with("CONTROL_SOLID") {
                    "options for tetrahedra and degenerate solids; palpa has hexahedra only"
                } else if name.starts_with("CONTROL_SHELL") || name.starts_with("CONTROL_RIGID") {
                    "shell and rigid-body options; palpa reads shells and rigid parts only as indenter surfaces"
                } else if name.starts_with("CONTROL_ACCURACY") {
                    "palpa's total Lagrangian elements are objective without it"
                } else {
                    "output or bookkeeping palpa does not write; docs/outputs.md lists what it writes"
                };
                d.warnings.push(format!("{}: {kw}: ignored ({why})", b.at));
            } else {
                return Err(format!(
                    "{}: {kw} is not supported and would change the model: {}",
                    b.at,
                    unsupported_hint(name)
                ));
            }
        }
    }
    Ok(())
}

/// LS-DYNA reads 0 in most real fields as "the default".
fn nonzero_or(x: f64, default: f64) -> f64 {
    if x == 0.0 {
        default
    } else {
        x
    }
}

fn nonzero_or_one(x: f64) -> f64 {
    nonzero_or(x, 1.0)
}

fn parse_mat(d: &mut Deck, b: &Block) -> Result<(), String> {
    let name = b.name.as_str();
    let (base, titled) = strip(name, "_TITLE");
    let kw = format!("*{name}");
    let mut c = Cards::new(b);
    if titled {
        c.title();
    }
    let (id, kind) = match base {
        "MAT_ELASTIC" | "MAT_001" => {
            let f = c.fields(MAT001)?;
            warn_fields(
                d,
                &f,
                &["DA", "DB"],
                "beam damping does not apply to solids",
            );
            (
                key(f.raw("MID")),
                MatKind::Elastic {
                    ro: f.real_req("RO")?,
                    e: f.real_req("E")?,
                    pr: f.real("PR", 0.0)?,
                },
            )
        }
        "MAT_OGDEN_RUBBER" | "MAT_077_O" => {
            let f = c.fields(MAT077)?;
            if f.int("N", 0)? > 0 {
                return Err(f.err("N", "fitting the constants to test data (N > 0) is not supported; give MU and ALPHA (N = 0)"));
            }
            if f.real("G", 0.0)? != 0.0 && f.real("SIGF", 0.0)? != 0.0 {
                return Err(f.err("SIGF", "frictional damping (G and SIGF) is not supported"));
            }
            if f.real("REF", 0.0)? == 1.0 {
                return Err(f.err(
                    "REF",
                    "a reference geometry (*INITIAL_FOAM_REFERENCE_GEOMETRY) is not supported",
                ));
            }
            let mu_f = c.fields(MU8)?;
            let al_f = c.fields(ALPHA8)?;
            let (mut mu, mut alpha) = (Vec::new(), Vec::new());
            for k in 0..8 {
                let m = mu_f.real(MU8[k].0, 0.0)?;
                let a = al_f.real(ALPHA8[k].0, 0.0)?;
                if m == 0.0 && a == 0.0 {
                    continue;
                }
                if a == 0.0 {
                    return Err(al_f.err(
                        ALPHA8[k].0,
                        format!("term {} has MU{} = {m} but no exponent", k + 1, k + 1),
                    ));
                }
                mu.push(m);
                alpha.push(a);
            }
            if mu.is_empty() {
                return Err(mu_f.err("MU1", "no Ogden term is given"));
            }
            let mut prony = Vec::new();
            for card in c.rest() {
                let p = fields(b, Some(card), PRONY)?;
                let gi = p.real("GI", 0.0)?;
                if gi == 0.0 {
                    continue;
                }
                let beta = p.real("BETAI", 0.0)?;
                if !(beta > 0.0) {
                    return Err(p.err(
                        "BETAI",
                        format!("the decay constant of a Prony term must be positive, got {beta}"),
                    ));
                }
                prony.push((gi, beta));
            }
            (
                key(f.raw("MID")),
                MatKind::Ogden {
                    ro: f.real_req("RO")?,
                    pr: f.real("PR", 0.0)?,
                    mu,
                    alpha,
                    prony,
                },
            )
        }
        "MAT_SIMPLIFIED_RUBBER/FOAM" | "MAT_SIMPLIFIED_RUBBER" | "MAT_181" => {
            let f = c.fields(MAT181)?;
            if f.real("SIGF", 0.0)? != 0.0 {
                return Err(f.err(
                    "SIGF",
                    "frictional damping is not supported (palpa's damping is MU)",
                ));
            }
            if f.real("REF", 0.0)? == 1.0 {
                return Err(f.err("REF", "a reference geometry is not supported"));
            }
            f.must_be("PRTEN", 0.0, "a tensile Poisson ratio is not supported")?;
            let g = c.fields(MAT181_2)?;
            g.must_be(
                "PR/BETA",
                0.0,
                "palpa's simplified rubber is given by KM and the curve, not by a Poisson ratio",
            )?;
            let lc = match g.int("LC/TBID", 0)? {
                0 => None,
                k if k < 0 => return Err(g.err("LC/TBID", "a negative curve id is not supported")),
                k => Some(k.to_string()),
            };
            if c.more() {
                let h = c.fields(MAT181_3)?;
                if h.int("LCUNLD", 0)? != 0 {
                    return Err(h.err("LCUNLD", "an unloading curve is not supported"));
                }
                let hu = h.real("HU", 1.0)?;
                if hu != 1.0 && !h.blank("HU") {
                    return Err(h.err("HU", "hysteretic unloading (HU < 1) is not supported"));
                }
                if h.real("VISCO", 0.0)? != 0.0 {
                    return Err(h.err("VISCO", "the viscoelastic option is not supported"));
                }
            }
            (
                key(f.raw("MID")),
                MatKind::SimplifiedRubber {
                    ro: f.real_req("RO")?,
                    km: f.real_req("KM")?,
                    mu: f.real("MU", 0.0)?,
                    g: f.real("G", 0.0)?,
                    gauge: [g.real("SGL", 1.0)?, g.real("SW", 1.0)?, g.real("ST", 1.0)?],
                    lc,
                },
            )
        }
        "MAT_PIECEWISE_LINEAR_PLASTICITY" | "MAT_024" => {
            let f = c.fields(MAT024)?;
            let g = c.fields(MAT024_2)?;
            g.must_be(
                "C",
                0.0,
                "strain-rate effects (Cowper-Symonds C, P) are not supported",
            )?;
            g.must_be(
                "P",
                0.0,
                "strain-rate effects (Cowper-Symonds C, P) are not supported",
            )?;
            if g.int("LCSR", 0)? != 0 {
                return Err(g.err("LCSR", "strain-rate effects are not supported"));
            }
            let e1 = c.fields(EPS8)?;
            let e2 = c.fields(ES8)?;
            let mut table = Vec::new();
            for k in 0..8 {
                let es = e2.real(ES8[k].0, 0.0)?;
                if es != 0.0 {
                    table.push((e1.real(EPS8[k].0, 0.0)?, es));
                }
            }
            let fail = f.real("FAIL", 0.0)?;
            if fail < 0.0 {
                return Err(f.err("FAIL", "a user failure subroutine is not supported"));
            }
            warn_fields(
                d,
                &f,
                &["TDEL"],
                "palpa erodes an element when its law fails, whatever its step",
            );
            (
                key(f.raw("MID")),
                MatKind::Plasticity {
                    ro: f.real_req("RO")?,
                    e: f.real_req("E")?,
                    pr: f.real("PR", 0.0)?,
                    sigy: f.real("SIGY", 0.0)?,
                    etan: f.real("ETAN", 0.0)?,
                    fail: (fail > 0.0 && fail < 1e20).then_some(fail),
                    lcss: match g.int("LCSS", 0)? {
                        0 => None,
                        k => Some(k.to_string()),
                    },
                    table,
                },
            )
        }
        "MAT_RIGID" | "MAT_020" => {
            let f = c.fields(MAT020)?;
            warn_fields(
                d,
                &f,
                &["N", "COUPLE", "M"],
                "coupling to MADYMO does not apply",
            );
            let g = c.fields(MAT020_2)?;
            let cmo = g.real("CMO", 0.0)?;
            if cmo < 0.0 {
                return Err(g.err(
                    "CMO",
                    "constraints in a local system (CMO = -1) are not supported",
                ));
            }
            (
                key(f.raw("MID")),
                MatKind::Rigid {
                    ro: f.real("RO", 0.0)?,
                    e: f.real("E", 0.0)?,
                    cmo,
                    con1: if cmo > 0.0 { g.int("CON1", 0)? } else { 0 },
                    con2: if cmo > 0.0 { g.int("CON2", 0)? } else { 0 },
                },
            )
        }
        _ => {
            return Err(format!(
                "{}: {kw} is not supported and would change the model: {}",
                b.at,
                unsupported_hint("MAT_")
            ))
        }
    };
    if id.is_empty() {
        return Err(format!("{}: {kw}: a material id (MID) is required", b.at));
    }
    d.mats.insert(
        id,
        MatCard {
            kind,
            keyword: kw,
            at: b.at.clone(),
            palpa: b.palpa.clone(),
        },
    );
    Ok(())
}

fn parse_set(d: &mut Deck, b: &Block) -> Result<(), String> {
    let name = b.name.as_str();
    let kw = format!("*{name}");
    let (base, titled) = strip(name, "_TITLE");
    let mut c = Cards::new(b);
    let title = titled.then(|| c.title());
    let (kind, generate) = match base {
        "SET_NODE" | "SET_NODE_LIST" => ("node", false),
        "SET_NODE_LIST_GENERATE" => ("node", true),
        "SET_PART" | "SET_PART_LIST" => ("part", false),
        "SET_PART_LIST_GENERATE" => ("part", true),
        "SET_SOLID" | "SET_SOLID_LIST" => ("solid", false),
        "SET_SOLID_GENERATE" => ("solid", true),
        "SET_SEGMENT" => ("segment", false),
        _ => {
            return Err(format!(
                "{}: {kw} is not supported; palpa reads *SET_NODE_LIST, *SET_PART_LIST, *SET_SOLID (each also _GENERATE) and *SET_SEGMENT",
                b.at
            ))
        }
    };
    let head = c.fields(if kind == "solid" {
        SET_SOLID_HEAD
    } else {
        SET_HEAD
    })?;
    let sid = head.int_req("SID")?;
    if kind == "segment" {
        let mut segments = Vec::new();
        for card in c.rest() {
            let f = fields(b, Some(card), SEGMENT)?;
            let n = [
                f.int_req("N1")?,
                f.int_req("N2")?,
                f.int_req("N3")?,
                f.int("N4", 0)?,
            ];
            segments.push([n[0], n[1], n[2], if n[3] == 0 { n[2] } else { n[3] }]);
        }
        d.segment_sets.insert(
            sid,
            SegmentSetCard {
                segments,
                at: b.at.clone(),
            },
        );
        return Ok(());
    }
    let mut ids: Vec<String> = Vec::new();
    for card in c.rest() {
        let f = fields(b, Some(card), IDS8)?;
        for k in ["ID1", "ID2", "ID3", "ID4", "ID5", "ID6", "ID7", "ID8"] {
            let t = f.raw(k);
            if !t.is_empty() && t != "0" {
                ids.push(t.to_string());
            }
        }
    }
    let ints = |ids: &[String]| -> Result<Vec<i64>, String> {
        ids.iter()
            .map(|s| {
                s.parse::<i64>()
                    .map_err(|_| format!("{}: {kw} {sid}: `{s}` is not an id", b.at))
            })
            .collect()
    };
    let ids: Vec<String> = if generate {
        let v = ints(&ids)?;
        if v.len() % 2 != 0 {
            return Err(format!(
                "{}: {kw} {sid}: ranges come in pairs (begin, end)",
                b.at
            ));
        }
        let mut out = Vec::new();
        for p in v.chunks(2) {
            if p[1] < p[0] || p[1] - p[0] > 100_000_000 {
                return Err(format!(
                    "{}: {kw} {sid}: range {} .. {} is not increasing",
                    b.at, p[0], p[1]
                ));
            }
            out.extend((p[0]..=p[1]).map(|i| i.to_string()));
        }
        out
    } else {
        ids
    };
    match kind {
        "node" => {
            d.node_sets.insert(
                sid,
                SetCard {
                    ids: ints(&ids)?,
                    title,
                    at: b.at.clone(),
                },
            );
        }
        "solid" => {
            d.solid_sets.insert(
                sid,
                SetCard {
                    ids: ints(&ids)?,
                    title,
                    at: b.at.clone(),
                },
            );
        }
        _ => {
            d.part_sets.insert(
                sid,
                PartSetCard {
                    ids: ids.iter().map(|s| key(s)).collect(),
                    at: b.at.clone(),
                },
            );
        }
    }
    Ok(())
}

fn parse_contact(d: &mut Deck, b: &Block) -> Result<(), String> {
    let name = b.name.as_str();
    let kw = format!("*{name}");
    let mut base = name;
    let mut with_id = false;
    let mut mpp = false;
    let mut notes = Vec::new();
    loop {
        if let Some(s) = base
            .strip_suffix("_ID")
            .or_else(|| base.strip_suffix("_TITLE"))
        {
            base = s;
            with_id = true;
        } else if let Some(s) = base.strip_suffix("_MPP") {
            base = s;
            mpp = true;
        } else if let Some(s) = base.strip_suffix("_MORTAR") {
            base = s;
            notes.push("_MORTAR: palpa runs its own penalty contact (docs/lsdyna.md), not LS-DYNA's mortar contact");
        } else if let Some(s) = base.strip_suffix("_SMOOTH") {
            base = s;
            notes.push("_SMOOTH: palpa's contact evaluates the rigid surface exactly as meshed");
        } else {
            break;
        }
    }
    let single = match base {
        "CONTACT_AUTOMATIC_SURFACE_TO_SURFACE" | "CONTACT_SURFACE_TO_SURFACE" => false,
        "CONTACT_AUTOMATIC_SINGLE_SURFACE" => true,
        _ => {
            return Err(format!(
                "{}: {kw} is not supported and would change the model: {}",
                b.at,
                unsupported_hint("CONTACT_")
            ))
        }
    };
    for n in notes {
        d.warnings.push(format!("{}: {kw}: {n}", b.at));
    }
    let mut c = Cards::new(b);
    if mpp {
        // One MPP card, and a second when it starts with '&'.
        c.next();
        if b.cards.get(1).is_some_and(|x| x.text.starts_with('&')) {
            c.next();
        }
    }
    if with_id {
        c.next();
    }
    let f1 = c.fields(CONTACT1)?;
    for n in ["SBOXID", "MBOXID"] {
        if f1.int(n, 0)? != 0 {
            return Err(f1.err(n, "contact boxes are not supported"));
        }
    }
    let f2 = c.fields(CONTACT2)?;
    if f2.real("VC", 0.0)? != 0.0 {
        return Err(f2.err("VC", "viscous friction is not supported"));
    }
    f2.must_be("BT", 0.0, "a contact is active for the whole run in palpa")?;
    let dt = f2.real("DT", 0.0)?;
    if dt != 0.0 && dt < 1e20 {
        return Err(f2.err("DT", "a contact is active for the whole run in palpa"));
    }
    warn_fields(
        d,
        &f2,
        &["PENCHK"],
        "palpa has no penetration check (it has no release of penetrating nodes)",
    );
    let f3 = c.fields(CONTACT3)?;
    for n in ["SFST", "SFMT", "FSF", "VSF"] {
        let v = f3.real(n, 1.0)?;
        if v != 1.0 && v != 0.0 {
            return Err(f3.err(n, format!("{v} is not supported (only the default 1)")));
        }
    }
    warn_fields(
        d,
        &f3,
        &["SST", "MST"],
        "palpa's contact surfaces have no thickness offset",
    );
    let (soft, sofscl) = if c.more() {
        let a = c.fields(CONTACT_A)?;
        warn_fields(
            d,
            &a,
            &["LCIDAB", "MAXPAR", "SBOPT", "DEPTH", "BSORT", "FRCFRQ"],
            "LS-DYNA's contact search options do not apply to palpa's contact",
        );
        (a.int("SOFT", 0)?, a.real("SOFSCL", 0.1)?)
    } else {
        (0, 0.1)
    };
    if ![0, 1].contains(&soft) {
        return Err(format!(
            "{}: {kw}, field SOFT: {soft} is not supported (0: penalty from the segment stiffness, 1: soft constraint; palpa has no segment-to-segment contact)",
            b.at
        ));
    }
    if c.more() {
        d.warnings.push(format!(
            "{}: {kw}: optional cards B and later ignored (LS-DYNA's contact options)",
            b.at
        ));
    }
    d.contacts.push(ContactCard {
        keyword: kw,
        single,
        ids: [f1.int("SSID", 0)?, f1.int("MSID", 0)?],
        types: [f1.int("SSTYP", 0)?, f1.int("MSTYP", 0)?],
        fs: f2.real("FS", 0.0)?,
        fd: f2.real("FD", 0.0)?,
        dc: f2.real("DC", 0.0)?,
        vdc: f2.real("VDC", 0.0)?,
        sf: [
            nonzero_or_one(f3.real("SFS", 1.0)?),
            nonzero_or_one(f3.real("SFM", 1.0)?),
        ],
        soft,
        sofscl: if sofscl == 0.0 { 0.1 } else { sofscl },
        at: b.at.clone(),
        palpa: b.palpa.clone(),
    });
    Ok(())
}
