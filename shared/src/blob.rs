//! The policy blob: the file that carries a greedy policy from the trainer
//! to the firmware.
//!
//! Layout, format versions 1 and 2 (all multi-byte integers little-endian):
//!
//! | offset       | size     | content                                        |
//! |--------------|----------|------------------------------------------------|
//! | 0            | 4        | magic `QPOL`                                   |
//! | 4            | 1        | format version (1 or 2)                        |
//! | 5            | 2        | body length `n` (u16)                          |
//! | 7            | n        | body, postcard-encoded (see [`PolicyBlob`])    |
//! | 7 + n        | 4        | CRC-32 (ISO-HDLC, as zlib) of bytes `0 .. 7+n` |
//!
//! The body holds, in order: hasher (its bit count, u8), action count (u8),
//! four angular speeds (f32, unused ones 0), forward speed (f32), field name
//! and free-text name (strings of at most 32 bytes), trainer steps and seed
//! (varint u64), then in version 1 the packed [`PolicyTable`] (byte
//! string, one action per state), in version 2 the packed [`ActionSets`]
//! (byte string, each state's best actions) and the sensor model and arena
//! the policy was trained for ([`TrainedFor`], two strings of at most 32
//! bytes, empty when not known).
//!
//! Decoding checks, in order: length of the fixed header, magic, version,
//! declared length against the input, CRC, then each body field. The first
//! failure is returned as a [`BlobError`]; decoding never panics.

use crate::action::{ActionId, ActionTable, ActionTableError};
use crate::action_sets::ActionSets;
use crate::hasher::{State, StateHasher};
use crate::policy::PolicyTable;
use core::fmt;
use crc::{Crc, CRC_32_ISO_HDLC};
use serde::{Deserialize, Serialize};

/// Longest field name or free-text name, in bytes.
pub const MAX_NAME_LEN: usize = 32;

/// A name of at most [`MAX_NAME_LEN`] bytes.
pub type Name = heapless::String<MAX_NAME_LEN>;

const CRC32: Crc<u32> = Crc::<u32>::new(&CRC_32_ISO_HDLC);
const HEADER_LEN: usize = 7;
const CRC_LEN: usize = 4;
/// Largest body: 2 + 16 + 4 + (1 + 32) x 2 + 10 x 2, then version 2's
/// (2 + 512) + (1 + 32) x 2 (version 1's table is at most 2 + 256).
const MAX_BODY_LEN: usize = 688;

/// Where a policy came from.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Provenance {
    /// The field the policy was trained on (e.g. `annulus`, `letter:T`).
    pub field: Name,
    /// A free-text name.
    pub name: Name,
    /// Trainer steps behind the policy.
    pub trainer_steps: u64,
    /// The trainer's seed.
    pub seed: u64,
}

/// Which of the names an error is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NameKind {
    /// [`Provenance::field`].
    Field,
    /// [`Provenance::name`].
    Name,
    /// [`TrainedFor::sensors`].
    Sensors,
    /// [`TrainedFor::arena`].
    Arena,
}

/// The sensor model and arena a policy was trained for (format version 2):
/// a policy learnt with the robot's senses on the TV acts on what those
/// senses report, so running it elsewhere is worth a word
/// (`host run`, `render` and `flash` compare them).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct TrainedFor {
    /// The sensor model (`disc`, `disc-thesis`, `robot`, ...).
    pub sensors: Name,
    /// The arena (`thesis`, `tv75`, an arena file's name).
    pub arena: Name,
}

impl TrainedFor {
    /// Trained-for names checked against [`MAX_NAME_LEN`].
    pub fn new(sensors: &str, arena: &str) -> Result<TrainedFor, BlobError> {
        Ok(TrainedFor {
            sensors: to_name(NameKind::Sensors, sensors)?,
            arena: to_name(NameKind::Arena, arena)?,
        })
    }
}

impl Provenance {
    /// Provenance with names checked against [`MAX_NAME_LEN`].
    pub fn new(
        field: &str,
        name: &str,
        trainer_steps: u64,
        seed: u64,
    ) -> Result<Provenance, BlobError> {
        Ok(Provenance {
            field: to_name(NameKind::Field, field)?,
            name: to_name(NameKind::Name, name)?,
            trainer_steps,
            seed,
        })
    }
}

/// The longest prefix of `s` of at most [`MAX_NAME_LEN`] bytes (cut at a
/// character boundary): a name that always fits.
pub fn name_prefix(s: &str) -> &str {
    let mut end = s.len().min(MAX_NAME_LEN);
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    &s[..end]
}

fn to_name(kind: NameKind, s: &str) -> Result<Name, BlobError> {
    Name::try_from(s).map_err(|_| BlobError::NameTooLong { kind, len: s.len() })
}

/// Every way a blob can be refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BlobError {
    /// The input ends before the blob does.
    Truncated {
        /// Bytes the blob needs.
        needed: usize,
        /// Bytes there are.
        found: usize,
    },
    /// The first four bytes are not `QPOL`: not a policy blob.
    WrongMagic([u8; 4]),
    /// A format version this build does not read.
    UnsupportedVersion(u8),
    /// Bytes after the end the header declares.
    TrailingBytes {
        /// Length the header declares, CRC included.
        expected: usize,
        /// Length of the input.
        found: usize,
    },
    /// The stored CRC does not match the content.
    CrcMismatch {
        /// CRC stored in the blob.
        stored: u32,
        /// CRC of the content.
        computed: u32,
    },
    /// The hasher id is not 7, 8, 9 or 10.
    UnknownHasher(u8),
    /// The packed table's length does not match the hasher.
    TableLength {
        /// The blob's hasher.
        hasher: StateHasher,
        /// Bytes the hasher needs.
        expected: usize,
        /// Bytes the blob holds.
        found: usize,
    },
    /// The action count is not 2 to 4.
    ActionCount(u8),
    /// An angular or forward speed is NaN or infinite.
    NonFiniteSpeed,
    /// A state's set of best actions is empty (format version 2).
    EmptyActionSet(State),
    /// A table entry names an action beyond the action count.
    ActionOutOfRange {
        /// The state whose entry is wrong.
        state: State,
        /// The action it names.
        action: ActionId,
        /// The blob's action count.
        count: u8,
    },
    /// A name is longer than [`MAX_NAME_LEN`] bytes.
    NameTooLong {
        /// Which name.
        kind: NameKind,
        /// Its length in bytes.
        len: usize,
    },
    /// The body does not decode (bad UTF-8, an overlong varint, unused bytes).
    Malformed(&'static str),
}

impl fmt::Display for BlobError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            BlobError::Truncated { needed, found } => {
                write!(
                    f,
                    "truncated policy blob: needs {needed} bytes, has {found}"
                )
            }
            BlobError::WrongMagic(m) => write!(
                f,
                "not a policy blob: magic bytes are {m:02x?}, expected \"QPOL\""
            ),
            BlobError::UnsupportedVersion(v) => {
                write!(
                    f,
                    "unsupported policy blob format version {v} (this build reads versions 1 to {})",
                    PolicyBlob::VERSION
                )
            }
            BlobError::TrailingBytes { expected, found } => {
                write!(
                    f,
                    "policy blob has {} bytes after its end ({expected} expected, {found} found)",
                    found - expected
                )
            }
            BlobError::CrcMismatch { stored, computed } => {
                write!(
                    f,
                    "policy blob is corrupt: CRC-32 is {computed:#010x}, blob says {stored:#010x}"
                )
            }
            BlobError::UnknownHasher(id) => {
                write!(f, "unknown state hasher id {id} (expected 7, 8, 9 or 10)")
            }
            BlobError::TableLength {
                hasher,
                expected,
                found,
            } => {
                write!(
                    f,
                    "policy table is {found} bytes but hasher {hasher} needs {expected}"
                )
            }
            BlobError::ActionCount(n) => write!(
                f,
                "action count {n} is out of range ({}..={})",
                ActionTable::MIN_ACTIONS,
                ActionTable::MAX_ACTIONS
            ),
            BlobError::NonFiniteSpeed => f.write_str("an action speed is not a finite number"),
            BlobError::EmptyActionSet(state) => {
                write!(f, "state {state} has no best action")
            }
            BlobError::ActionOutOfRange {
                state,
                action,
                count,
            } => {
                write!(
                    f,
                    "state {state} maps to action {action} but the table has {count} actions"
                )
            }
            BlobError::NameTooLong { kind, len } => {
                let which = match kind {
                    NameKind::Field => "field name",
                    NameKind::Name => "name",
                    NameKind::Sensors => "sensor model name",
                    NameKind::Arena => "arena name",
                };
                write!(
                    f,
                    "{which} is {len} bytes long, at most {MAX_NAME_LEN} allowed"
                )
            }
            BlobError::Malformed(why) => write!(f, "malformed policy blob body: {why}"),
        }
    }
}

impl core::error::Error for BlobError {}

impl From<ActionTableError> for BlobError {
    fn from(e: ActionTableError) -> BlobError {
        match e {
            ActionTableError::CountOutOfRange(n) => BlobError::ActionCount(n.min(255) as u8),
            ActionTableError::NonFiniteSpeed => BlobError::NonFiniteSpeed,
        }
    }
}

/// The version 1 body as it is on the wire; the header and CRC wrap it.
#[derive(Serialize, Deserialize)]
struct Body<'a> {
    hasher: u8,
    action_count: u8,
    angular_speeds: [f32; ActionTable::MAX_ACTIONS],
    forward_speed: f32,
    field: &'a str,
    name: &'a str,
    trainer_steps: u64,
    seed: u64,
    #[serde(borrow)]
    table: &'a [u8],
}

/// The version 2 body: version 1's with action sets in place of the table,
/// then what the policy was trained for.
#[derive(Serialize, Deserialize)]
struct BodyV2<'a> {
    hasher: u8,
    action_count: u8,
    angular_speeds: [f32; ActionTable::MAX_ACTIONS],
    forward_speed: f32,
    field: &'a str,
    name: &'a str,
    trainer_steps: u64,
    seed: u64,
    #[serde(borrow)]
    sets: &'a [u8],
    sensors: &'a str,
    arena: &'a str,
}

/// An encoded blob.
pub type EncodedBlob = heapless::Vec<u8, { PolicyBlob::MAX_ENCODED_LEN }>;

/// A greedy policy with everything needed to run it: the hasher (carried
/// by the table), the actions, each state's best actions, where it came
/// from and what it was trained for.
#[derive(Clone, Debug, PartialEq)]
pub struct PolicyBlob {
    actions: ActionTable,
    table: PolicyTable,
    sets: ActionSets,
    provenance: Provenance,
    trained_for: Option<TrainedFor>,
}

impl PolicyBlob {
    /// The magic bytes every blob starts with.
    pub const MAGIC: [u8; 4] = *b"QPOL";
    /// The newest format version this build writes and reads (it reads
    /// every version from 1).
    pub const VERSION: u8 = 2;
    /// The format version of a blob with one action per state and nothing
    /// about what it was trained for: what every build before version 2
    /// wrote, and what [`PolicyBlob::encode`] still writes for such a blob.
    pub const VERSION_1: u8 = 1;
    /// Upper bound of an encoded blob's size (1024 states, longest names).
    pub const MAX_ENCODED_LEN: usize = HEADER_LEN + MAX_BODY_LEN + CRC_LEN;

    /// A blob, checked: every table entry must name one of the actions.
    pub fn new(
        actions: ActionTable,
        table: PolicyTable,
        provenance: Provenance,
    ) -> Result<PolicyBlob, BlobError> {
        if let Some((state, action)) = table.entries().find(|(_, a)| a.index() >= actions.len()) {
            return Err(BlobError::ActionOutOfRange {
                state,
                action,
                count: actions.len() as u8,
            });
        }
        Ok(PolicyBlob {
            actions,
            sets: ActionSets::of_table(&table),
            table,
            provenance,
            trained_for: None,
        })
    }

    /// A blob from each state's best actions, checked: no set is empty and
    /// every action is one of `actions`. Its [`PolicyBlob::table`] is each
    /// set's lowest action.
    pub fn with_sets(
        actions: ActionTable,
        sets: ActionSets,
        provenance: Provenance,
    ) -> Result<PolicyBlob, BlobError> {
        for (state, mask) in sets.masks() {
            if mask == 0 {
                return Err(BlobError::EmptyActionSet(state));
            }
            let highest = 7 - mask.leading_zeros() as usize;
            if highest >= actions.len() {
                return Err(BlobError::ActionOutOfRange {
                    state,
                    action: ActionId(highest as u8),
                    count: actions.len() as u8,
                });
            }
        }
        Ok(PolicyBlob {
            actions,
            table: sets.lowest(),
            sets,
            provenance,
            trained_for: None,
        })
    }

    /// This blob, recording the sensor model and arena it was trained for.
    pub fn with_trained_for(mut self, trained_for: TrainedFor) -> PolicyBlob {
        self.trained_for = Some(trained_for);
        self
    }

    /// The sensor model and arena the policy was trained for, if the blob
    /// says (format version 2 with them given).
    pub fn trained_for(&self) -> Option<&TrainedFor> {
        self.trained_for.as_ref()
    }

    /// Each state's best actions; a blob of version 1 has one per state,
    /// its table's.
    pub fn sets(&self) -> &ActionSets {
        &self.sets
    }

    /// The format version [`PolicyBlob::encode`] writes: 2 when the blob
    /// has a state with two or more best actions or says what it was
    /// trained for, else 1 (so that such a blob is byte for byte what
    /// builds before version 2 wrote).
    pub fn version(&self) -> u8 {
        if self.trained_for.is_some() || self.sets.has_ties() {
            Self::VERSION
        } else {
            Self::VERSION_1
        }
    }

    /// The state hasher the table is indexed by.
    pub fn hasher(&self) -> StateHasher {
        self.table.hasher()
    }

    /// The actions the table's entries refer to.
    pub fn actions(&self) -> &ActionTable {
        &self.actions
    }

    /// The greedy policy table.
    pub fn table(&self) -> &PolicyTable {
        &self.table
    }

    /// Where the policy came from.
    pub fn provenance(&self) -> &Provenance {
        &self.provenance
    }

    /// Encodes the blob, in format version [`PolicyBlob::version`].
    pub fn encode(&self) -> EncodedBlob {
        let mut angular_speeds = [0.0; ActionTable::MAX_ACTIONS];
        angular_speeds[..self.actions.len()].copy_from_slice(self.actions.angular_speeds());
        let version = self.version();
        let mut buf = [0u8; PolicyBlob::MAX_ENCODED_LEN];
        let out = &mut buf[HEADER_LEN..HEADER_LEN + MAX_BODY_LEN];
        let written = if version == Self::VERSION_1 {
            postcard::to_slice(
                &Body {
                    hasher: self.hasher().id(),
                    action_count: self.actions.len() as u8,
                    angular_speeds,
                    forward_speed: self.actions.forward_speed(),
                    field: &self.provenance.field,
                    name: &self.provenance.name,
                    trainer_steps: self.provenance.trainer_steps,
                    seed: self.provenance.seed,
                    table: self.table.packed(),
                },
                out,
            )
            .map(|b| b.len())
        } else {
            let trained_for = self.trained_for.clone().unwrap_or_default();
            postcard::to_slice(
                &BodyV2 {
                    hasher: self.hasher().id(),
                    action_count: self.actions.len() as u8,
                    angular_speeds,
                    forward_speed: self.actions.forward_speed(),
                    field: &self.provenance.field,
                    name: &self.provenance.name,
                    trainer_steps: self.provenance.trainer_steps,
                    seed: self.provenance.seed,
                    sets: self.sets.packed(),
                    sensors: &trained_for.sensors,
                    arena: &trained_for.arena,
                },
                out,
            )
            .map(|b| b.len())
        };
        let body_len = written.expect(
            "a body never exceeds MAX_BODY_LEN: names and tables are bounded by their types",
        );
        buf[..4].copy_from_slice(&Self::MAGIC);
        buf[4] = version;
        buf[5..7].copy_from_slice(&(body_len as u16).to_le_bytes());
        let end = HEADER_LEN + body_len;
        let crc = CRC32.checksum(&buf[..end]);
        buf[end..end + CRC_LEN].copy_from_slice(&crc.to_le_bytes());
        let mut out = EncodedBlob::new();
        // Cannot fail: `end + CRC_LEN <= MAX_ENCODED_LEN`, the vector's capacity.
        let _ = out.extend_from_slice(&buf[..end + CRC_LEN]);
        out
    }

    /// Decodes and checks a blob.
    pub fn decode(bytes: &[u8]) -> Result<PolicyBlob, BlobError> {
        if bytes.len() < HEADER_LEN {
            return Err(BlobError::Truncated {
                needed: HEADER_LEN,
                found: bytes.len(),
            });
        }
        let magic = [bytes[0], bytes[1], bytes[2], bytes[3]];
        if magic != Self::MAGIC {
            return Err(BlobError::WrongMagic(magic));
        }
        let version = bytes[4];
        if version != Self::VERSION_1 && version != Self::VERSION {
            return Err(BlobError::UnsupportedVersion(version));
        }
        let body_len = usize::from(u16::from_le_bytes([bytes[5], bytes[6]]));
        let end = HEADER_LEN + body_len;
        let total = end + CRC_LEN;
        if bytes.len() < total {
            return Err(BlobError::Truncated {
                needed: total,
                found: bytes.len(),
            });
        }
        if bytes.len() > total {
            return Err(BlobError::TrailingBytes {
                expected: total,
                found: bytes.len(),
            });
        }
        let stored =
            u32::from_le_bytes([bytes[end], bytes[end + 1], bytes[end + 2], bytes[end + 3]]);
        let computed = CRC32.checksum(&bytes[..end]);
        if stored != computed {
            return Err(BlobError::CrcMismatch { stored, computed });
        }
        let body_bytes = &bytes[HEADER_LEN..end];
        if version == Self::VERSION_1 {
            let body: Body<'_> = take_body(body_bytes)?;
            let (hasher, actions) = hasher_and_actions(
                body.hasher,
                body.action_count,
                &body.angular_speeds,
                body.forward_speed,
            )?;
            let table =
                PolicyTable::from_packed(hasher, body.table).ok_or(BlobError::TableLength {
                    hasher,
                    expected: PolicyTable::packed_len(hasher),
                    found: body.table.len(),
                })?;
            let provenance = Provenance::new(body.field, body.name, body.trainer_steps, body.seed)?;
            PolicyBlob::new(actions, table, provenance)
        } else {
            let body: BodyV2<'_> = take_body(body_bytes)?;
            let (hasher, actions) = hasher_and_actions(
                body.hasher,
                body.action_count,
                &body.angular_speeds,
                body.forward_speed,
            )?;
            let sets =
                ActionSets::from_packed(hasher, body.sets).ok_or(BlobError::TableLength {
                    hasher,
                    expected: ActionSets::packed_len(hasher),
                    found: body.sets.len(),
                })?;
            let provenance = Provenance::new(body.field, body.name, body.trainer_steps, body.seed)?;
            let trained_for = TrainedFor::new(body.sensors, body.arena)?;
            let blob = PolicyBlob::with_sets(actions, sets, provenance)?;
            Ok(if trained_for == TrainedFor::default() {
                blob
            } else {
                blob.with_trained_for(trained_for)
            })
        }
    }
}

/// A body of either version, all of `bytes` used.
fn take_body<'a, T: Deserialize<'a>>(bytes: &'a [u8]) -> Result<T, BlobError> {
    let (body, rest): (T, &[u8]) = postcard::take_from_bytes(bytes).map_err(|e| match e {
        postcard::Error::DeserializeUnexpectedEnd => BlobError::Truncated {
            needed: bytes.len() + 1,
            found: bytes.len(),
        },
        postcard::Error::DeserializeBadUtf8 => BlobError::Malformed("a name is not valid UTF-8"),
        postcard::Error::DeserializeBadVarint => {
            BlobError::Malformed("an integer is not a valid varint")
        }
        _ => BlobError::Malformed("the body does not decode"),
    })?;
    if !rest.is_empty() {
        return Err(BlobError::Malformed(
            "the body is shorter than its declared length",
        ));
    }
    Ok(body)
}

/// The hasher and actions of a body of either version.
fn hasher_and_actions(
    hasher: u8,
    action_count: u8,
    angular_speeds: &[f32; ActionTable::MAX_ACTIONS],
    forward_speed: f32,
) -> Result<(StateHasher, ActionTable), BlobError> {
    let id = hasher;
    let hasher = StateHasher::from_id(id).ok_or(BlobError::UnknownHasher(id))?;
    let count = usize::from(action_count);
    if !(ActionTable::MIN_ACTIONS..=ActionTable::MAX_ACTIONS).contains(&count) {
        return Err(BlobError::ActionCount(action_count));
    }
    let actions = ActionTable::new(&angular_speeds[..count], forward_speed)?;
    Ok((hasher, actions))
}
