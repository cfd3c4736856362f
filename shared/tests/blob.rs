//! Policy blob format: round trips, corruption, typed errors, stability.

use proptest::prelude::*;
use serde::Serialize;
use shared::blob::NameKind;
use shared::{
    ActionId, ActionSets, ActionTable, BlobError, PolicyBlob, PolicyTable, Provenance, State,
    StateHasher, TrainedFor,
};

const LONG_NAME: &str = "abcdefghijklmnopqrstuvwxyz012345"; // 32 bytes

fn sample(hasher: StateHasher, actions: ActionTable) -> PolicyBlob {
    let mut table = PolicyTable::new(hasher);
    for s in 0..hasher.num_states() as u16 {
        let a = (s as usize * 7 + s as usize / 5) % actions.len();
        table.set(State(s), ActionId(a as u8));
    }
    let provenance = Provenance::new(LONG_NAME, LONG_NAME, 5_000_000, u64::MAX).unwrap();
    PolicyBlob::new(actions, table, provenance).unwrap()
}

fn default_blob() -> PolicyBlob {
    sample(StateHasher::Original, ActionTable::default())
}

/// The wire body, written out independently of the crate's private type,
/// so these tests also pin the format.
#[derive(Serialize)]
struct WireBody<'a> {
    hasher: u8,
    action_count: u8,
    angular_speeds: [f32; 4],
    forward_speed: f32,
    field: &'a str,
    name: &'a str,
    trainer_steps: u64,
    seed: u64,
    table: &'a [u8],
}

impl WireBody<'_> {
    fn valid(table: &[u8]) -> WireBody<'_> {
        WireBody {
            hasher: 8,
            action_count: 4,
            angular_speeds: [0.3, 0.15, -0.15, -0.3],
            forward_speed: 2.0,
            field: "annulus",
            name: "test",
            trainer_steps: 10,
            seed: 1,
            table,
        }
    }
}

/// Header + body + a correct CRC around arbitrary body bytes.
fn frame(version: u8, body: &[u8]) -> Vec<u8> {
    let mut out = b"QPOL".to_vec();
    out.push(version);
    out.extend_from_slice(&(body.len() as u16).to_le_bytes());
    out.extend_from_slice(body);
    let crc = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC).checksum(&out);
    out.extend_from_slice(&crc.to_le_bytes());
    out
}

fn framed(body: &WireBody<'_>) -> Vec<u8> {
    frame(1, &postcard::to_allocvec(body).unwrap())
}

#[test]
fn round_trip_for_every_hasher_and_action_count() {
    for hasher in StateHasher::ALL {
        for n in 2..=4 {
            let actions = ActionTable::new(&ActionTable::DEFAULT_ANGULAR[..n], 1.5).unwrap();
            let blob = sample(hasher, actions);
            let bytes = blob.encode();
            assert_eq!(
                PolicyBlob::decode(&bytes),
                Ok(blob.clone()),
                "{hasher} with {n} actions"
            );
        }
    }
}

#[test]
fn a_256_state_blob_with_longest_names_is_at_most_200_bytes() {
    let bytes = default_blob().encode();
    assert!(bytes.len() <= 200, "{} bytes", bytes.len());
    let largest = sample(StateHasher::OriginalObstacle, ActionTable::default()).encode();
    assert!(largest.len() <= PolicyBlob::MAX_ENCODED_LEN);
}

#[test]
fn hand_built_wire_body_decodes_like_the_encoder_writes_it() {
    let blob = default_blob();
    let body = WireBody {
        field: LONG_NAME,
        name: LONG_NAME,
        trainer_steps: 5_000_000,
        seed: u64::MAX,
        ..WireBody::valid(blob.table().packed())
    };
    assert_eq!(framed(&body), blob.encode().to_vec());
}

#[test]
fn every_single_bit_flip_is_rejected() {
    let bytes = default_blob().encode();
    for i in 0..bytes.len() * 8 {
        let mut corrupt = bytes.to_vec();
        corrupt[i / 8] ^= 1 << (i % 8);
        assert!(
            PolicyBlob::decode(&corrupt).is_err(),
            "flip of bit {i} accepted"
        );
    }
}

#[test]
fn every_truncation_is_rejected() {
    let bytes = default_blob().encode();
    for len in 0..bytes.len() {
        let err = PolicyBlob::decode(&bytes[..len]).unwrap_err();
        assert!(
            matches!(err, BlobError::Truncated { .. }),
            "length {len}: {err:?}"
        );
    }
}

#[test]
fn wrong_magic() {
    let mut bytes = framed(&WireBody::valid(&[0; 64]));
    bytes[0] = b'X';
    assert_eq!(
        PolicyBlob::decode(&bytes),
        Err(BlobError::WrongMagic(*b"XPOL"))
    );
    let png = b"\x89PNG\r\n\x1a\n....";
    assert!(matches!(
        PolicyBlob::decode(png),
        Err(BlobError::WrongMagic(_))
    ));
}

#[test]
fn unsupported_version() {
    let body = postcard::to_allocvec(&WireBody::valid(&[0; 64])).unwrap();
    for version in [0, 3, 255] {
        assert_eq!(
            PolicyBlob::decode(&frame(version, &body)),
            Err(BlobError::UnsupportedVersion(version))
        );
    }
}

#[test]
fn crc_mismatch() {
    let mut bytes = framed(&WireBody::valid(&[0; 64]));
    let n = bytes.len();
    bytes[n - 1] ^= 0x80;
    assert!(matches!(
        PolicyBlob::decode(&bytes),
        Err(BlobError::CrcMismatch { .. })
    ));
    let mut bytes = framed(&WireBody::valid(&[0; 64]));
    bytes[20] ^= 1;
    assert!(matches!(
        PolicyBlob::decode(&bytes),
        Err(BlobError::CrcMismatch { .. })
    ));
}

#[test]
fn unknown_hasher() {
    let bytes = framed(&WireBody {
        hasher: 11,
        ..WireBody::valid(&[0; 64])
    });
    assert_eq!(
        PolicyBlob::decode(&bytes),
        Err(BlobError::UnknownHasher(11))
    );
}

#[test]
fn table_length_that_does_not_match_the_hasher() {
    let bytes = framed(&WireBody::valid(&[0; 63]));
    assert_eq!(
        PolicyBlob::decode(&bytes),
        Err(BlobError::TableLength {
            hasher: StateHasher::Original,
            expected: 64,
            found: 63
        })
    );
    let bytes = framed(&WireBody {
        hasher: 10,
        ..WireBody::valid(&[0; 64])
    });
    assert!(matches!(
        PolicyBlob::decode(&bytes),
        Err(BlobError::TableLength {
            expected: 256,
            found: 64,
            ..
        })
    ));
}

#[test]
fn action_count_out_of_range() {
    for count in [0u8, 1, 5, 255] {
        let bytes = framed(&WireBody {
            action_count: count,
            ..WireBody::valid(&[0; 64])
        });
        assert_eq!(
            PolicyBlob::decode(&bytes),
            Err(BlobError::ActionCount(count))
        );
    }
}

#[test]
fn table_entry_beyond_the_action_count() {
    let mut table = [0u8; 64];
    table[3] = 0b10 << 4; // state 14 -> action 2
    let bytes = framed(&WireBody {
        action_count: 2,
        ..WireBody::valid(&table)
    });
    assert_eq!(
        PolicyBlob::decode(&bytes),
        Err(BlobError::ActionOutOfRange {
            state: State(14),
            action: ActionId(2),
            count: 2
        })
    );
}

#[test]
fn truncated_body_with_a_correct_crc() {
    let body = postcard::to_allocvec(&WireBody::valid(&[0; 64])).unwrap();
    let bytes = frame(1, &body[..body.len() - 10]);
    assert!(matches!(
        PolicyBlob::decode(&bytes),
        Err(BlobError::Truncated { .. })
    ));
}

#[test]
fn trailing_bytes_and_unused_body_bytes() {
    let mut bytes = framed(&WireBody::valid(&[0; 64]));
    bytes.push(0);
    assert!(matches!(
        PolicyBlob::decode(&bytes),
        Err(BlobError::TrailingBytes { .. })
    ));
    let mut body = postcard::to_allocvec(&WireBody::valid(&[0; 64])).unwrap();
    body.push(0);
    assert!(matches!(
        PolicyBlob::decode(&frame(1, &body)),
        Err(BlobError::Malformed(_))
    ));
}

#[test]
fn non_finite_speed_and_long_names() {
    let bytes = framed(&WireBody {
        forward_speed: f32::NAN,
        ..WireBody::valid(&[0; 64])
    });
    assert_eq!(PolicyBlob::decode(&bytes), Err(BlobError::NonFiniteSpeed));
    let long = "x".repeat(33);
    let bytes = framed(&WireBody {
        name: &long,
        ..WireBody::valid(&[0; 64])
    });
    assert_eq!(
        PolicyBlob::decode(&bytes),
        Err(BlobError::NameTooLong {
            kind: NameKind::Name,
            len: 33
        })
    );
    let bytes = framed(&WireBody {
        field: &long,
        ..WireBody::valid(&[0; 64])
    });
    assert_eq!(
        PolicyBlob::decode(&bytes),
        Err(BlobError::NameTooLong {
            kind: NameKind::Field,
            len: 33
        })
    );
    assert!(Provenance::new(&long, "", 0, 0).is_err());
}

#[test]
fn errors_say_what_is_wrong() {
    let text = BlobError::TableLength {
        hasher: StateHasher::Original,
        expected: 64,
        found: 63,
    }
    .to_string();
    assert!(
        text.contains("63") && text.contains("64") && text.contains("original"),
        "{text}"
    );
    let text = BlobError::WrongMagic(*b"\x89PNG").to_string();
    assert!(text.contains("not a policy blob"), "{text}");
}

/// `tests/data/golden-v1.policy` was written by the first build of the
/// format; every later build must still read it the same way.
#[test]
fn golden_blob_still_decodes() {
    let bytes = include_bytes!("data/golden-v1.policy");
    let blob = PolicyBlob::decode(bytes).expect("golden blob decodes");
    assert_eq!(blob, default_blob());
    assert_eq!(blob.provenance().field.as_str(), LONG_NAME);
    assert_eq!(
        blob.table().action(State(101)),
        ActionId(((101 * 7 + 101 / 5) % 4) as u8)
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]
    #[test]
    fn decoder_never_panics_on_arbitrary_bytes(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        let _ = PolicyBlob::decode(&bytes);
    }

    #[test]
    fn decoder_never_panics_on_framed_arbitrary_bodies(body in proptest::collection::vec(any::<u8>(), 0..400)) {
        // A correct header and CRC around garbage reaches the body decoder.
        let _ = PolicyBlob::decode(&frame(1, &body));
        let _ = PolicyBlob::decode(&frame(2, &body));
    }

    #[test]
    fn decoder_never_panics_on_mutated_version_2_blobs(
        edits in proptest::collection::vec((0usize..400, any::<u8>()), 1..8)
    ) {
        let mut bytes = tied(StateHasher::Original, ActionTable::default()).encode().to_vec();
        for (i, b) in edits {
            let n = bytes.len();
            bytes[i % n] = b;
        }
        let _ = PolicyBlob::decode(&bytes);
    }

    #[test]
    fn decoder_never_panics_on_mutated_valid_blobs(
        edits in proptest::collection::vec((0usize..200, any::<u8>()), 1..8)
    ) {
        let mut bytes = default_blob().encode().to_vec();
        for (i, b) in edits {
            let n = bytes.len();
            bytes[i % n] = b;
        }
        let _ = PolicyBlob::decode(&bytes);
    }
}

#[test]
fn every_error_type_is_a_standard_error() {
    fn is_error<E: std::error::Error + Send + Sync + 'static>(_: &E) {}
    is_error(&shared::BlobError::NonFiniteSpeed);
    is_error(&shared::LogError::BadCobs);
    is_error(&shared::ActionTableError::NonFiniteSpeed);
}

// ---- format version 2: each state's best actions and what it was trained for

/// A blob with a mix of one-, two-, three- and all-action sets (as many as
/// the action count allows) that says what it was trained for.
fn tied(hasher: StateHasher, actions: ActionTable) -> PolicyBlob {
    let all = (1u8 << actions.len()) - 1;
    let mut sets = ActionSets::new(hasher);
    for s in 0..hasher.num_states() as u16 {
        let mask = ((s as u8).wrapping_mul(7) ^ (s / 3) as u8) & all;
        sets.set(State(s), if mask == 0 { all } else { mask });
    }
    let provenance = Provenance::new(LONG_NAME, LONG_NAME, 5_000_000, u64::MAX).unwrap();
    PolicyBlob::with_sets(actions, sets, provenance)
        .unwrap()
        .with_trained_for(TrainedFor::new("robot", LONG_NAME).unwrap())
}

/// The version 2 wire body, written out independently of the crate.
#[derive(Serialize)]
struct WireBodyV2<'a> {
    hasher: u8,
    action_count: u8,
    angular_speeds: [f32; 4],
    forward_speed: f32,
    field: &'a str,
    name: &'a str,
    trainer_steps: u64,
    seed: u64,
    sets: &'a [u8],
    sensors: &'a str,
    arena: &'a str,
}

fn framed_v2(sets: &[u8], sensors: &str, arena: &str) -> Vec<u8> {
    let body = WireBodyV2 {
        hasher: 8,
        action_count: 4,
        angular_speeds: [0.3, 0.15, -0.15, -0.3],
        forward_speed: 2.0,
        field: "annulus",
        name: "test",
        trainer_steps: 10,
        seed: 1,
        sets,
        sensors,
        arena,
    };
    frame(2, &postcard::to_allocvec(&body).unwrap())
}

#[test]
fn a_version_2_blob_round_trips_for_every_hasher_and_action_count() {
    for hasher in StateHasher::ALL {
        for n in 2..=4 {
            let actions = ActionTable::new(&ActionTable::DEFAULT_ANGULAR[..n], 1.5).unwrap();
            let blob = tied(hasher, actions);
            let bytes = blob.encode();
            assert_eq!(bytes[4], 2, "{hasher} with {n} actions");
            assert!(bytes.len() <= PolicyBlob::MAX_ENCODED_LEN);
            let back = PolicyBlob::decode(&bytes).unwrap();
            assert_eq!(back, blob, "{hasher} with {n} actions");
            assert_eq!(back.sets(), blob.sets());
            assert_eq!(back.trained_for(), blob.trained_for());
        }
    }
}

#[test]
fn a_version_2_blob_is_the_documented_wire_body() {
    let mut sets = ActionSets::new(StateHasher::Original);
    for s in 0..256u16 {
        sets.set(State(s), if s % 5 == 0 { 0b1010 } else { 0b0001 });
    }
    let provenance = Provenance::new("annulus", "test", 10, 1).unwrap();
    let blob = PolicyBlob::with_sets(ActionTable::default(), sets.clone(), provenance)
        .unwrap()
        .with_trained_for(TrainedFor::new("disc", "thesis").unwrap());
    assert_eq!(
        blob.encode().to_vec(),
        framed_v2(sets.packed(), "disc", "thesis")
    );
    // its table, for whatever wants one action, is each set's lowest
    assert_eq!(blob.table().action(State(5)), ActionId(1));
    assert_eq!(blob.table().action(State(6)), ActionId(0));
}

#[test]
fn a_blob_without_ties_or_trained_for_is_still_written_as_version_1() {
    let blob = default_blob();
    assert_eq!(blob.version(), 1);
    assert_eq!(blob.encode()[4], 1);
    let with = blob
        .clone()
        .with_trained_for(TrainedFor::new("disc", "thesis").unwrap());
    assert_eq!(with.version(), 2);
    // a version 1 blob decodes to single-action sets: its table's
    let back = PolicyBlob::decode(&blob.encode()).unwrap();
    assert_eq!(back.sets(), &ActionSets::of_table(blob.table()));
    assert_eq!(back.trained_for(), None);
}

#[test]
fn every_single_bit_flip_of_a_version_2_blob_is_rejected() {
    for hasher in [StateHasher::Original, StateHasher::OriginalObstacle] {
        let bytes = tied(hasher, ActionTable::default()).encode();
        for i in 0..bytes.len() * 8 {
            let mut corrupt = bytes.to_vec();
            corrupt[i / 8] ^= 1 << (i % 8);
            assert!(
                PolicyBlob::decode(&corrupt).is_err(),
                "{hasher}: flip of bit {i} accepted"
            );
        }
    }
}

#[test]
fn every_truncation_of_a_version_2_blob_is_rejected() {
    let bytes = tied(StateHasher::Original, ActionTable::default()).encode();
    for len in 0..bytes.len() {
        let err = PolicyBlob::decode(&bytes[..len]).unwrap_err();
        assert!(
            matches!(err, BlobError::Truncated { .. }),
            "length {len}: {err:?}"
        );
    }
}

#[test]
fn version_2_refuses_empty_sets_missing_actions_wrong_lengths_and_long_names() {
    let mut sets = [0x11u8; 128];
    sets[3] = 0x10; // state 6's set is empty
    assert_eq!(
        PolicyBlob::decode(&framed_v2(&sets, "disc", "thesis")),
        Err(BlobError::EmptyActionSet(State(6)))
    );
    let two = ActionTable::new(&[0.3, -0.3], 2.0).unwrap();
    let mut beyond = ActionSets::new(StateHasher::Original);
    for s in 0..256u16 {
        beyond.set(State(s), 0b0001);
    }
    beyond.set(State(9), 0b0101);
    assert_eq!(
        PolicyBlob::with_sets(two, beyond, Provenance::default()),
        Err(BlobError::ActionOutOfRange {
            state: State(9),
            action: ActionId(2),
            count: 2
        })
    );
    assert!(matches!(
        PolicyBlob::decode(&framed_v2(&[0x11; 64], "disc", "thesis")),
        Err(BlobError::TableLength {
            expected: 128,
            found: 64,
            ..
        })
    ));
    let long = "x".repeat(33);
    assert!(matches!(
        PolicyBlob::decode(&framed_v2(&[0x11; 128], &long, "thesis")),
        Err(BlobError::NameTooLong {
            kind: NameKind::Sensors,
            len: 33
        })
    ));
    assert!(matches!(
        TrainedFor::new("disc", &long),
        Err(BlobError::NameTooLong {
            kind: NameKind::Arena,
            ..
        })
    ));
    // empty trained-for names read as "not known"
    let unknown = PolicyBlob::decode(&framed_v2(&[0x31; 128], "", "")).unwrap();
    assert_eq!(unknown.trained_for(), None);
    assert!(unknown.sets().has_ties());
}
