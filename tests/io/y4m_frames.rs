//! YUV4MPEG2 frames: exact round trips for every layout, buffers reused, truncated
//! and malformed frames named, huge headers with little data fail fast, frames that do
//! not fit refused.

use super::*;

#[test]
fn write_read_round_trip_is_exact_for_every_layout() {
    let mut rng = Rng(0x1234_5678);
    for chroma in Chroma::ALL {
        for (w, h) in [(7u32, 5u32), (16, 8), (1, 1)] {
            let mut hd = header(w, h, chroma);
            hd.fps = (30000, 1001);
            hd.interlace = Interlace::TopFieldFirst;
            hd.aspect = (16, 15);
            hd.extra = vec!["COLORRANGE=LIMITED".into(), "VENDOR=fx".into()];
            let frames: Vec<YuvFrame> = (0..3)
                .map(|i| {
                    let mut f = random_frame(&hd, &mut rng);
                    if i == 1 {
                        f.params = vec!["Itpi".into(), "Xfoo=1".into()];
                    }
                    f
                })
                .collect();
            let mut w8 = Y4mWriter::new(Vec::new(), hd.clone(), "mem").unwrap();
            for f in &frames {
                w8.write_frame(f).unwrap();
            }
            assert_eq!(w8.frames_written(), 3);
            let bytes = w8.into_inner().unwrap();

            // Exact bytes: header line, then FRAME lines and the planes.
            let line = format!(
                "YUV4MPEG2 W{w} H{h} F30000:1001 It A16:15 C{} XCOLORRANGE=LIMITED XVENDOR=fx\n",
                chroma.tag()
            );
            let mut want = line.into_bytes();
            for f in &frames {
                want.extend_from_slice(b"FRAME");
                for p in &f.params {
                    want.push(b' ');
                    want.extend_from_slice(p.as_bytes());
                }
                want.push(b'\n');
                want.extend_from_slice(&f.y);
                want.extend_from_slice(&f.u);
                want.extend_from_slice(&f.v);
            }
            assert_eq!(bytes, want, "{chroma} {w}x{h}");
            let (cw, ch) = chroma.chroma_size(w, h);
            assert_eq!(
                frames[0].u.len(),
                cw * ch,
                "{chroma} {w}x{h} chroma plane size"
            );

            let mut r = Y4mReader::new(Cursor::new(bytes), "mem").unwrap();
            assert_eq!(r.header(), &hd);
            for (i, f) in frames.iter().enumerate() {
                assert_eq!(r.next_frame().unwrap().as_ref(), Some(f), "frame {i}");
            }
            assert_eq!(r.next_frame().unwrap(), None);
            assert_eq!(r.frames_read(), 3);
        }
    }
    // Plane sizes of 4:2:0 / 4:2:2 with odd sides round up.
    assert_eq!(Chroma::C420Jpeg.chroma_size(7, 5), (4, 3));
    assert_eq!(Chroma::C422.chroma_size(7, 5), (4, 5));
    assert_eq!(Chroma::C444.chroma_size(7, 5), (7, 5));
    assert_eq!(Chroma::Mono.chroma_size(7, 5), (0, 0));
    assert_eq!(Chroma::Mono.frame_bytes(7, 5), 35);
}

#[test]
fn reader_reuses_buffers_and_iterates() {
    let hd = header(32, 16, Chroma::C420Jpeg);
    let mut rng = Rng(9);
    let frames: Vec<YuvFrame> = (0..4).map(|_| random_frame(&hd, &mut rng)).collect();
    let mut w = Y4mWriter::new(Vec::new(), hd.clone(), "mem").unwrap();
    for f in &frames {
        w.write_frame(f).unwrap();
    }
    let bytes = w.into_inner().unwrap();
    let mut r = Y4mReader::new(Cursor::new(bytes.clone()), "mem").unwrap();
    let mut buf = YuvFrame::default();
    assert!(r.read_frame_into(&mut buf).unwrap());
    let ptr = buf.y.as_ptr();
    assert!(r.read_frame_into(&mut buf).unwrap());
    assert_eq!(buf.y.as_ptr(), ptr, "the luma buffer is reused");
    assert_eq!(buf, frames[1]);
    let all: Vec<YuvFrame> = Y4mReader::new(Cursor::new(bytes), "mem")
        .unwrap()
        .map(Result::unwrap)
        .collect();
    assert_eq!(all, frames);
}

#[test]
fn truncated_and_malformed_frames_name_the_frame() {
    let hd = header(720, 576, Chroma::C420Jpeg);
    let mut rng = Rng(77);
    let mut w = Y4mWriter::new(Vec::new(), hd.clone(), "stdin").unwrap();
    for _ in 0..3 {
        w.write_frame(&random_frame(&hd, &mut rng)).unwrap();
    }
    let full = w.into_inner().unwrap();
    let header_len = hd.to_line().len();
    let frame_len = 6 + 622_080;
    assert_eq!(full.len(), header_len + 3 * frame_len);

    // Cut 1000 bytes into frame 2's planes.
    let cut = header_len + 2 * frame_len + 6 + 1000;
    let mut r = Y4mReader::new(Cursor::new(full[..cut].to_vec()), "stdin").unwrap();
    assert!(r.next_frame().unwrap().is_some());
    assert!(r.next_frame().unwrap().is_some());
    let e = r.next_frame().unwrap_err();
    assert_eq!(
        e.to_string(),
        "stdin: y4m frame 2 (0-based): truncated (got 1000 of 622080 bytes)"
    );
    assert_eq!(e.frame(), Some(2));
    let io: IoError = e.into();
    assert!(matches!(io, IoError::Decode { .. }));
    assert_eq!(
        io.to_string(),
        "stdin: y4m frame 2 (0-based): truncated (got 1000 of 622080 bytes)"
    );
    // Truncated inside the chroma planes: the count covers all planes.
    let cut = header_len + frame_len + 6 + 414_720 + 10;
    let e = second_frame_error(full[..cut].to_vec(), "in.y4m");
    assert_eq!(
        e.to_string(),
        "in.y4m: y4m frame 1 (0-based): truncated (got 414730 of 622080 bytes)"
    );
    // The iterator stops after an error.
    let it = Y4mReader::new(Cursor::new(full[..cut].to_vec()), "in.y4m").unwrap();
    let results: Vec<bool> = it.map(|r| r.is_ok()).collect();
    assert_eq!(results, [true, false]);

    // Truncated inside the FRAME line.
    let cut = header_len + frame_len + 3;
    let e = second_frame_error(full[..cut].to_vec(), "stdin");
    assert!(
        e.to_string().starts_with(
            "stdin: y4m frame 1 (0-based): truncated: the stream ends inside the FRAME line"
        ),
        "{e}"
    );

    // A malformed FRAME line.
    let mut bad = full.clone();
    bad[header_len + frame_len..header_len + frame_len + 5].copy_from_slice(b"FRAMX");
    let e = second_frame_error(bad, "stdin");
    assert!(
        e.to_string()
            .starts_with("stdin: y4m frame 1 (0-based): expected a `FRAME` line, found \"FRAMX"),
        "{e}"
    );
    // Extra bytes after a frame (the frame size disagrees with the header).
    let mut bad = full[..header_len + frame_len].to_vec();
    bad.extend_from_slice(b"\0\0FRAME\n");
    let e = second_frame_error(bad, "stdin");
    assert!(
        e.to_string()
            .contains("frame 1 (0-based): expected a `FRAME` line"),
        "{e}"
    );
    // A clean end right after the header: no frames.
    let mut r = Y4mReader::new(Cursor::new(full[..header_len].to_vec()), "stdin").unwrap();
    assert_eq!(r.next_frame().unwrap(), None);
}

#[test]
fn huge_header_with_little_data_fails_fast() {
    // 16384 x 16384 4:4:4 announces 805 MB per frame; only 10 bytes follow.
    let mut bytes = b"YUV4MPEG2 W16384 H16384 C444\nFRAME\n".to_vec();
    bytes.extend_from_slice(&[0; 10]);
    let t = Instant::now();
    let mut r = Y4mReader::new(Cursor::new(bytes), "stdin").unwrap();
    let e = r.next_frame().unwrap_err();
    assert_eq!(
        e.to_string(),
        "stdin: y4m frame 0 (0-based): truncated (got 10 of 805306368 bytes)"
    );
    assert!(t.elapsed().as_secs_f64() < 2.0, "{:?}", t.elapsed());
}

#[test]
fn writer_rejects_frames_that_do_not_fit() {
    let hd = header(8, 4, Chroma::C420Jpeg);
    let mut w = Y4mWriter::new(Vec::new(), hd.clone(), "stdout").unwrap();
    let mut f = YuvFrame::black(&hd, Range::Limited);
    f.u.pop();
    let e = w.write_frame(&f).unwrap_err();
    assert_eq!(
        e.to_string(),
        "stdout: y4m frame 0 (0-based): the Cb plane has 7 bytes, the header (8x4 C420jpeg) needs 8"
    );
    let mut f = YuvFrame::black(&hd, Range::Limited);
    f.params = vec!["a b".into()];
    assert!(w.write_frame(&f).is_err());
    let mut bad = hd.clone();
    bad.width = 0;
    assert!(Y4mWriter::new(Vec::new(), bad, "stdout").is_err());
    let mut bad = hd;
    bad.extra = vec!["has space".into()];
    assert!(Y4mWriter::new(Vec::new(), bad, "stdout").is_err());
}

// ---------------------------------------------------------------------------------------
