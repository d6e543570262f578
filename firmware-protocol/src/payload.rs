//! The byte layout of every message's payload, shared by the CAN and serial mappings.
//!
//! All multi-byte fields are **little-endian**; offsets are in bytes. "pos" is a
//! [`Position`] slot (`u16`, 0.01 mm, `0xFFFF` = none); "act" is an actuator index 0..=7 or
//! `0xFF` for the whole node; "set" is an [`ActuatorSet`] bit mask.
//!
//! | code | message                  | len | layout                                                         |
//! |-----:|--------------------------|----:|----------------------------------------------------------------|
//! |    0 | EmergencyStop            |   0 | –                                                              |
//! |    1 | Sync                     |   2 | 0–1 duration ms `u16`                                          |
//! |    2 | Emergency                |   7 | 0–1 code `u16`, 2 act, 3–6 detail `i32`                        |
//! |  3/4 | TargetsLower/Upper       |   8 | 0–7 four pos (actuators 0–3 / 4–7)                             |
//! |    5 | AllTargets               |  16 | 0–15 eight pos (actuators 0–7)                                 |
//! |  6/7 | FeedbackLower/Upper      |   8 | as 3/4                                                         |
//! |    8 | AllFeedback              |  16 | as 5                                                           |
//! |    9 | HostHeartbeat            |   2 | 0 protocol major, 1 protocol minor                             |
//! |   10 | Heartbeat                |   6 | 0 state, 1–2 faults `u16`, 3 homed set, 4 moving set, 5 staged set |
//! |   11 | Control                  |   1 | 0 command                                                      |
//! |   12 | Home                     |   1 | 0 set                                                          |
//! |   13 | MotionLimits             |   5 | 0 set, 1–2 max speed `u16` 0.01 mm/s, 3–4 max accel `u16` 0.1 mm/s² |
//! |   14 | IdentifyRequest          |   0 | –                                                              |
//! |   15 | Identity                 |   6 | 0–1 protocol major/minor, 2–4 firmware major/minor/patch, 5 actuator count |
//! |   16 | Capabilities             |   6 | 0–1 stroke pos, 2–3 max speed, 4–5 max accel                   |
//! |   17 | ParamRead                |   3 | 0–1 param id `u16`, 2 act                                      |
//! | 18/19| ParamWrite/ParamValue    |   7 | 0–1 param id `u16`, 2 act, 3–6 value `i32`                     |
//! |   20 | Ack                      |   2 | 0 request code, 1 status                                       |
//! |21/22 | ForceLower/Upper (1.1)   |   8 | 0–7 four force `i16` 0.01 N (actuators 0–3 / 4–7), `0x8000` = none |
//! |   23 | AllForce (1.1)           |  16 | 0–15 eight force `i16` (actuators 0–7)                         |
//!
//! Decoding rules (the safety net both sides rely on): a payload shorter than its layout is
//! rejected ([`Error::Truncated`]); bytes past the layout are ignored (a newer minor version
//! may append fields); an enumeration value, actuator index or count out of range is
//! rejected ([`Error::InvalidField`]). Decoding never panics and never allocates.

use crate::Error;
use crate::actuator::{
    Accel, ActuatorSet, Force, Position, Speed, actuator_from_wire, actuator_to_wire,
    force_to_wire, position_from_wire, position_to_wire,
};
use crate::drive::{AckStatus, DriveCommand, DriveState, EmergencyCode, Faults};
use crate::message::{
    Ack, Capabilities, Code, Emergency, Forces4, Forces8, Half, Heartbeat, HostHeartbeat, Identity,
    Message, MotionLimits, Param, ParamRead, Positions4, Positions8, Sync,
};
use crate::param::ParamId;
use crate::version::{FirmwareVersion, ProtocolVersion};

/// The longest payload of this version (`AllTargets`, `AllFeedback`, `AllForce`).
pub const MAX_LEN: usize = 16;

/// An encoded payload: at most [`MAX_LEN`] bytes, no allocation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Payload {
    bytes: [u8; MAX_LEN],
    len: usize,
}

impl Payload {
    /// The bytes.
    pub fn as_slice(&self) -> &[u8] {
        &self.bytes[..self.len]
    }

    // Encoders write at most `Code::payload_len` ≤ MAX_LEN bytes, so this cannot overflow.
    fn put(&mut self, bytes: &[u8]) {
        self.bytes[self.len..self.len + bytes.len()].copy_from_slice(bytes);
        self.len += bytes.len();
    }

    fn u8(&mut self, value: u8) {
        self.put(&[value]);
    }

    fn u16(&mut self, value: u16) {
        self.put(&value.to_le_bytes());
    }

    fn i32(&mut self, value: i32) {
        self.put(&value.to_le_bytes());
    }

    fn positions(&mut self, positions: &[Option<Position>]) {
        for &p in positions {
            self.u16(position_to_wire(p));
        }
    }

    fn forces(&mut self, forces: &[Option<Force>]) {
        for &f in forces {
            self.put(&force_to_wire(f).to_le_bytes());
        }
    }
}

/// Encodes a message's payload.
pub fn encode(message: &Message) -> Payload {
    let mut out = Payload { bytes: [0; MAX_LEN], len: 0 };
    match message {
        Message::EmergencyStop | Message::IdentifyRequest => {}
        Message::Sync(m) => out.u16(m.duration_ms),
        Message::Emergency(m) => {
            out.u16(m.code.0);
            out.u8(actuator_to_wire(m.actuator));
            out.i32(m.detail);
        }
        Message::Targets(m) | Message::Feedback(m) => out.positions(&m.positions),
        Message::AllTargets(m) | Message::AllFeedback(m) => out.positions(&m.positions),
        Message::HostHeartbeat(m) => {
            out.u8(m.protocol.major);
            out.u8(m.protocol.minor);
        }
        Message::Heartbeat(m) => {
            out.u8(m.state as u8);
            out.u16(m.faults.bits());
            out.u8(m.homed.bits());
            out.u8(m.moving.bits());
            out.u8(m.staged.bits());
        }
        Message::Control(command) => out.u8(*command as u8),
        Message::Home(actuators) => out.u8(actuators.bits()),
        Message::MotionLimits(m) => {
            out.u8(m.actuators.bits());
            out.u16(m.max_speed.hundredths_mm_s());
            out.u16(m.max_accel.tenths_mm_s2());
        }
        Message::Identity(m) => {
            out.put(&[m.protocol.major, m.protocol.minor]);
            out.put(&[m.firmware.major, m.firmware.minor, m.firmware.patch]);
            out.u8(m.actuator_count);
        }
        Message::Capabilities(m) => {
            out.u16(m.stroke.hundredths_mm());
            out.u16(m.max_speed.hundredths_mm_s());
            out.u16(m.max_accel.tenths_mm_s2());
        }
        Message::ParamRead(m) => {
            out.u16(m.param.0);
            out.u8(actuator_to_wire(m.actuator));
        }
        Message::ParamWrite(m) | Message::ParamValue(m) => {
            out.u16(m.param.0);
            out.u8(actuator_to_wire(m.actuator));
            out.i32(m.value);
        }
        Message::Ack(m) => {
            out.u8(m.request as u8);
            out.u8(m.status as u8);
        }
        Message::Force(m) => out.forces(&m.forces),
        Message::AllForce(m) => out.forces(&m.forces),
    }
    out
}

/// Reads fields off the front of a payload.
struct Reader<'a>(&'a [u8]);

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], Error> {
        let (head, rest) = self.0.split_first_chunk::<N>().ok_or(Error::Truncated)?;
        self.0 = rest;
        Ok(*head)
    }

    fn u8(&mut self) -> Result<u8, Error> {
        Ok(self.take::<1>()?[0])
    }

    fn u16(&mut self) -> Result<u16, Error> {
        self.take().map(u16::from_le_bytes)
    }

    fn i32(&mut self) -> Result<i32, Error> {
        self.take().map(i32::from_le_bytes)
    }

    fn actuator(&mut self) -> Result<Option<crate::Actuator>, Error> {
        actuator_from_wire(self.u8()?).map_err(|()| Error::InvalidField("actuator"))
    }

    fn set(&mut self) -> Result<ActuatorSet, Error> {
        self.u8().map(ActuatorSet::from_bits)
    }

    fn positions<const N: usize>(&mut self) -> Result<[Option<Position>; N], Error> {
        let mut positions = [None; N];
        for p in &mut positions {
            *p = position_from_wire(self.u16()?);
        }
        Ok(positions)
    }

    fn forces<const N: usize>(&mut self) -> Result<[Option<Force>; N], Error> {
        let mut forces = [None; N];
        for f in &mut forces {
            *f = Force::new(self.take().map(i16::from_le_bytes)?);
        }
        Ok(forces)
    }

    fn protocol(&mut self) -> Result<ProtocolVersion, Error> {
        let [major, minor] = self.take()?;
        Ok(ProtocolVersion { major, minor })
    }

    fn param(&mut self) -> Result<Param, Error> {
        Ok(Param { param: ParamId(self.u16()?), actuator: self.actuator()?, value: self.i32()? })
    }
}

/// Decodes the payload of a message with function code `code`.
pub fn decode(code: Code, payload: &[u8]) -> Result<Message, Error> {
    let r = &mut Reader(payload);
    let four =
        |r: &mut Reader, half| Ok::<_, Error>(Positions4 { half, positions: r.positions()? });
    Ok(match code {
        Code::EmergencyStop => Message::EmergencyStop,
        Code::Sync => Message::Sync(Sync { duration_ms: r.u16()? }),
        Code::Emergency => Message::Emergency(Emergency {
            code: EmergencyCode(r.u16()?),
            actuator: r.actuator()?,
            detail: r.i32()?,
        }),
        Code::TargetsLower => Message::Targets(four(r, Half::Lower)?),
        Code::TargetsUpper => Message::Targets(four(r, Half::Upper)?),
        Code::AllTargets => Message::AllTargets(Positions8 { positions: r.positions()? }),
        Code::FeedbackLower => Message::Feedback(four(r, Half::Lower)?),
        Code::FeedbackUpper => Message::Feedback(four(r, Half::Upper)?),
        Code::AllFeedback => Message::AllFeedback(Positions8 { positions: r.positions()? }),
        Code::HostHeartbeat => Message::HostHeartbeat(HostHeartbeat { protocol: r.protocol()? }),
        Code::Heartbeat => Message::Heartbeat(Heartbeat {
            state: DriveState::from_u8(r.u8()?).ok_or(Error::InvalidField("state"))?,
            faults: Faults::from_bits_retain(r.u16()?),
            homed: r.set()?,
            moving: r.set()?,
            staged: r.set()?,
        }),
        Code::Control => {
            Message::Control(DriveCommand::from_u8(r.u8()?).ok_or(Error::InvalidField("command"))?)
        }
        Code::Home => Message::Home(r.set()?),
        Code::MotionLimits => Message::MotionLimits(MotionLimits {
            actuators: r.set()?,
            max_speed: Speed::from_hundredths_mm_s(r.u16()?),
            max_accel: Accel::from_tenths_mm_s2(r.u16()?),
        }),
        Code::IdentifyRequest => Message::IdentifyRequest,
        Code::Identity => Message::Identity(Identity {
            protocol: r.protocol()?,
            firmware: {
                let [major, minor, patch] = r.take()?;
                FirmwareVersion { major, minor, patch }
            },
            actuator_count: match r.u8()? {
                count @ 1..=8 => count,
                _ => return Err(Error::InvalidField("actuator_count")),
            },
        }),
        Code::Capabilities => Message::Capabilities(Capabilities {
            stroke: position_from_wire(r.u16()?).ok_or(Error::InvalidField("stroke"))?,
            max_speed: Speed::from_hundredths_mm_s(r.u16()?),
            max_accel: Accel::from_tenths_mm_s2(r.u16()?),
        }),
        Code::ParamRead => {
            Message::ParamRead(ParamRead { param: ParamId(r.u16()?), actuator: r.actuator()? })
        }
        Code::ParamWrite => Message::ParamWrite(r.param()?),
        Code::ParamValue => Message::ParamValue(r.param()?),
        Code::Ack => Message::Ack(Ack {
            request: Code::from_u8(r.u8()?).ok_or(Error::InvalidField("request"))?,
            status: AckStatus::from_u8(r.u8()?).ok_or(Error::InvalidField("status"))?,
        }),
        Code::ForceLower => Message::Force(Forces4 { half: Half::Lower, forces: r.forces()? }),
        Code::ForceUpper => Message::Force(Forces4 { half: Half::Upper, forces: r.forces()? }),
        Code::AllForce => Message::AllForce(Forces8 { forces: r.forces()? }),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Actuator;

    #[test]
    fn emergency_layout_is_little_endian_code_actuator_detail() {
        let m = Message::Emergency(Emergency {
            code: EmergencyCode::OVERCURRENT,
            actuator: Actuator::new(5),
            detail: -2,
        });
        assert_eq!(encode(&m).as_slice(), [0x10, 0x23, 5, 0xFE, 0xFF, 0xFF, 0xFF]);
    }

    #[test]
    fn heartbeat_layout_puts_faults_in_bytes_1_and_2() {
        let m = Message::Heartbeat(Heartbeat {
            state: DriveState::Fault,
            faults: Faults::HOMING_FAILED | Faults::EMERGENCY_STOP,
            homed: ActuatorSet::from_bits(0x0F),
            moving: ActuatorSet::EMPTY,
            staged: ActuatorSet::from_bits(0x80),
        });
        assert_eq!(encode(&m).as_slice(), [3, 0x01, 0x01, 0x0F, 0, 0x80]);
        // The README's example: the same after an e-stop only.
        let Message::Heartbeat(h) = m else { unreachable!() };
        let readme = Message::Heartbeat(Heartbeat { faults: Faults::EMERGENCY_STOP, ..h });
        assert_eq!(encode(&readme).as_slice(), [0x03, 0x01, 0x00, 0x0F, 0x00, 0x80]);
    }

    #[test]
    fn every_payload_has_its_code_length() {
        for code in Code::ALL {
            let zeros = [0u8; MAX_LEN];
            // Some layouts reject all-zero bytes (actuator count 0); the length is what counts.
            let message = decode(code, &zeros).or_else(|_| decode(code, &[1; MAX_LEN]));
            let message = message.unwrap_or_else(|e| panic!("{code:?}: {e}"));
            assert_eq!(encode(&message).as_slice().len(), code.payload_len(), "{code:?}");
        }
    }

    #[test]
    fn force_layout_is_signed_hundredths_of_a_newton_with_0x8000_for_none() {
        let m = Message::Force(Forces4 {
            half: Half::Upper,
            forces: [Force::new(1234), None, Force::new(-2), Some(Force::ZERO)],
        });
        assert_eq!(encode(&m).as_slice(), [0xD2, 0x04, 0x00, 0x80, 0xFE, 0xFF, 0, 0]);
        assert_eq!(decode(Code::ForceUpper, encode(&m).as_slice()), Ok(m));
    }

    #[test]
    fn short_payloads_are_truncated_long_ones_accepted() {
        assert_eq!(decode(Code::Sync, &[1]), Err(Error::Truncated));
        assert_eq!(decode(Code::Sync, &[1, 2, 3]), Ok(Message::Sync(Sync { duration_ms: 0x0201 })));
    }

    #[test]
    fn out_of_range_fields_are_rejected() {
        assert_eq!(decode(Code::Heartbeat, &[4, 0, 0, 0, 0, 0]), Err(Error::InvalidField("state")));
        assert_eq!(decode(Code::Control, &[9]), Err(Error::InvalidField("command")));
        assert_eq!(decode(Code::Ack, &[1, 99]), Err(Error::InvalidField("status")));
        assert_eq!(decode(Code::Ack, &[24, 0]), Err(Error::InvalidField("request")));
        assert_eq!(decode(Code::ParamRead, &[1, 0, 8]), Err(Error::InvalidField("actuator")));
        assert_eq!(
            decode(Code::Identity, &[1, 0, 1, 2, 3, 9]),
            Err(Error::InvalidField("actuator_count"))
        );
        assert_eq!(
            decode(Code::Capabilities, &[0xFF, 0xFF, 0, 0, 0, 0]),
            Err(Error::InvalidField("stroke"))
        );
    }
}
