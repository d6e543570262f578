//! The in-process CAN bus: arbitration, exact frame timing, per-port order, load counters,
//! the candump log and the bus faults, under tokio's paused clock.

use embedded_can::{Frame as _, StandardId};
use firmware_protocol::budget;
use firmware_protocol::can::Frame;
use form_sim::bus::can::{BusError, CanBus, CanKind, RX_QUEUE};
use form_sim::bus::candump::CandumpLog;
use form_sim::fault::FaultSpec;
use tokio::time::{Duration, Instant, sleep};

fn frame(id: u16, len: usize) -> Frame {
    Frame::new(StandardId::new(id).unwrap(), &vec![0xA5; len]).unwrap()
}

fn ns(kind: CanKind, len: usize) -> Duration {
    Duration::from_nanos(kind.budget().frame_time_ns(len))
}

const BIT: Duration = Duration::from_micros(1);

#[tokio::test(start_paused = true)]
async fn the_lowest_identifier_wins_and_frames_follow_back_to_back() {
    let bus = CanBus::new(CanKind::CLASSIC_1M);
    let (a, b, c, mut listener) = (bus.attach(), bus.attach(), bus.attach(), bus.attach());
    let t0 = Instant::now();
    a.queue(frame(0x300, 8)).unwrap();
    b.queue(frame(0x100, 2)).unwrap();
    c.queue(frame(0x200, 0)).unwrap();
    let mut got = Vec::new();
    for _ in 0..3 {
        let r = listener.recv_timed().await.unwrap();
        got.push((r.frame.standard_id().as_raw(), r.at - t0));
    }
    let kind = CanKind::CLASSIC_1M;
    let first = BIT + ns(kind, 2);
    let second = first + ns(kind, 0);
    assert_eq!(got, [(0x100, first), (0x200, second), (0x300, second + ns(kind, 8))]);
    assert_eq!(ns(kind, 8), Duration::from_micros(135), "budget::classic_frame_bits(8)");
    let stats = bus.stats();
    assert_eq!((stats.frames, stats.busy), (3, ns(kind, 2) + ns(kind, 0) + ns(kind, 8)));
}

#[tokio::test(start_paused = true)]
async fn a_port_sends_in_order_and_never_hears_itself() {
    let bus = CanBus::new(CanKind::CLASSIC_1M);
    let (mut host, other, mut listener) = (bus.attach(), bus.attach(), bus.attach());
    // Set-points then SYNC from one port: the SYNC's higher priority must not overtake them.
    host.queue(frame(0x0C1, 8)).unwrap();
    host.queue(frame(0x040, 2)).unwrap();
    other.queue(frame(0x081, 7)).unwrap();
    let mut order = Vec::new();
    for _ in 0..3 {
        order.push(listener.recv().await.unwrap().standard_id().as_raw());
    }
    assert_eq!(order, [0x081, 0x0C1, 0x040]);
    sleep(Duration::from_millis(5)).await;
    assert_eq!(host.try_recv().map(|f| f.standard_id().as_raw()), Some(0x081));
    assert_eq!(host.try_recv(), None, "the host heard its own frames");
}

#[tokio::test(start_paused = true)]
async fn send_returns_once_the_frame_has_crossed_the_bus() {
    let bus = CanBus::new(CanKind::CLASSIC_1M);
    let port = bus.attach();
    let t0 = Instant::now();
    port.send(frame(0x123, 8)).await.unwrap();
    // The receivers get it at the first timer tick after its end (tokio's timer is 1 ms).
    assert_eq!(Instant::now() - t0, Duration::from_millis(1));
    assert_eq!(bus.stats().frames, 1);
}

#[tokio::test(start_paused = true)]
async fn fd_frames_need_an_fd_bus_and_use_its_data_rate() {
    let all = Frame::new(StandardId::new(0x145).unwrap(), &[1; 16]).unwrap();
    let classic = CanBus::new(CanKind::CLASSIC_1M);
    assert_eq!(classic.attach().send(all).await, Err(BusError::FdOnClassicBus));
    let fd = CanBus::new(CanKind::FD_1M_5M);
    let (port, mut listener) = (fd.attach(), fd.attach());
    let t0 = Instant::now();
    port.queue(all).unwrap();
    let received = listener.recv_timed().await.unwrap();
    assert_eq!(received.frame, all);
    let bits = budget::fd_frame_bits(16);
    let expected =
        Duration::from_nanos(u64::from(bits.nominal) * 1000 + u64::from(bits.data) * 200);
    assert_eq!(received.at - t0, BIT + expected);
}

#[tokio::test(start_paused = true)]
async fn the_log_has_every_frame_with_its_exact_time() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bus.log");
    let bus = CanBus::with(
        CanKind::CLASSIC_1M,
        &FaultSpec::default(),
        Some(CandumpLog::create(&path, "can0").unwrap()),
    );
    let (a, mut listener) = (bus.attach(), bus.attach());
    a.queue(frame(0x283, 6)).unwrap();
    a.queue(frame(0x040, 2)).unwrap();
    listener.recv().await.unwrap();
    listener.recv().await.unwrap();
    bus.flush_log().unwrap();
    let log = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = log.lines().collect();
    assert_eq!(lines.len(), 2, "{log}");
    assert!(lines[0].ends_with(" can0 283#A5A5A5A5A5A5"), "{}", lines[0]);
    assert!(lines[1].ends_with(" can0 040#A5A5"), "{}", lines[1]);
    let time = |line: &str| line[1..line.find(')').unwrap()].parse::<f64>().unwrap();
    let gap = time(lines[1]) - time(lines[0]);
    let expected = ns(CanKind::CLASSIC_1M, 2).as_secs_f64();
    assert!((gap - expected).abs() < 1.5e-6, "{gap} s between back-to-back frames");
}

#[tokio::test(start_paused = true)]
async fn dropped_frames_take_bus_time_but_reach_nobody() {
    let faults: FaultSpec = "drop=0.3,seed=3".parse().unwrap();
    let bus = CanBus::with(CanKind::CLASSIC_1M, &faults, None);
    let (port, mut listener) = (bus.attach(), bus.attach());
    for i in 0..200 {
        port.send(frame(0x100 + i, 8)).await.unwrap();
    }
    sleep(Duration::from_millis(2)).await;
    let mut received = 0;
    while listener.try_recv().is_some() {
        received += 1;
    }
    let stats = bus.stats();
    assert_eq!(stats.frames, 200);
    assert!((40..80).contains(&stats.dropped), "{} dropped", stats.dropped);
    assert_eq!(received, 200 - stats.dropped);
    assert_eq!(stats.busy, 200 * ns(CanKind::CLASSIC_1M, 8));
}

#[tokio::test(start_paused = true)]
async fn corrupted_frames_are_retransmitted_after_an_error_frame() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bus.log");
    let faults: FaultSpec = "corrupt=0.2,seed=5".parse().unwrap();
    let log = CandumpLog::create(&path, "can0").unwrap();
    let bus = CanBus::with(CanKind::CLASSIC_1M, &faults, Some(log));
    let (port, mut listener) = (bus.attach(), bus.attach());
    for i in 0..100 {
        port.queue(frame(0x200 + i, 8)).unwrap();
    }
    for i in 0..100 {
        // Nothing is lost and the order holds.
        assert_eq!(listener.recv().await.unwrap().standard_id().as_raw(), 0x200 + i);
    }
    let stats = bus.stats();
    assert!(stats.error_frames > 5, "{} error frames", stats.error_frames);
    assert_eq!(stats.frames, 100);
    assert!(stats.busy > 100 * ns(CanKind::CLASSIC_1M, 8));
    bus.flush_log().unwrap();
    let log = std::fs::read_to_string(&path).unwrap();
    let errors = log.lines().filter(|l| l.ends_with("20000080#0000000000000000")).count();
    assert_eq!(errors as u64, stats.error_frames);
}

#[tokio::test(start_paused = true)]
async fn a_delay_hands_frames_over_later() {
    let faults: FaultSpec = "delay=5ms".parse().unwrap();
    let bus = CanBus::with(CanKind::CLASSIC_1M, &faults, None);
    let (port, mut listener) = (bus.attach(), bus.attach());
    let t0 = Instant::now();
    port.queue(frame(0x100, 0)).unwrap();
    let received = listener.recv_timed().await.unwrap();
    let expected = BIT + ns(CanKind::CLASSIC_1M, 0) + Duration::from_millis(5);
    assert_eq!(received.at - t0, expected);
}

#[tokio::test(start_paused = true)]
async fn during_bus_off_every_frame_fails() {
    let faults: FaultSpec = "busoff@10ms..20ms".parse().unwrap();
    let bus = CanBus::with(CanKind::CLASSIC_1M, &faults, None);
    let port = bus.attach();
    assert_eq!(port.send(frame(0x100, 1)).await, Ok(()));
    sleep(Duration::from_millis(10)).await;
    assert_eq!(port.send(frame(0x100, 1)).await, Err(BusError::BusOff));
    sleep(Duration::from_millis(10)).await;
    assert_eq!(port.send(frame(0x100, 1)).await, Ok(()));
    assert_eq!((bus.stats().frames, bus.stats().bus_off), (2, 1));
}

#[tokio::test(start_paused = true)]
async fn a_port_that_does_not_read_overruns_instead_of_growing() {
    let bus = CanBus::new(CanKind::CLASSIC_1M);
    let (port, _deaf) = (bus.attach(), bus.attach());
    for _ in 0..RX_QUEUE + 10 {
        port.queue(frame(0x100, 0)).unwrap();
    }
    sleep(Duration::from_secs(1)).await;
    assert_eq!(bus.stats().overruns, 10);
}

#[tokio::test(start_paused = true)]
async fn dropping_the_bus_closes_its_ports() {
    let bus = CanBus::new(CanKind::CLASSIC_1M);
    let mut port = bus.attach();
    drop(bus);
    assert_eq!(port.recv().await, None);
    assert_eq!(port.queue(frame(0x100, 0)), Err(BusError::Closed));
}
