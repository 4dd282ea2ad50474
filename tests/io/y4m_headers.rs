//! YUV4MPEG2 headers: fields parsed and written back, interlacing reported,
//! malformed headers rejected cleanly.

use super::*;

#[test]
fn header_fields_are_parsed_and_written_back() {
    let line =
        "YUV4MPEG2 W720 H576 F25:1 Ib A16:15 C420mpeg2 XYSCSS=420MPEG2 XCOLORRANGE=LIMITED\n";
    let h = Y4mHeader::parse(line.as_bytes()).unwrap();
    assert_eq!((h.width, h.height), (720, 576));
    assert_eq!(h.fps, (25, 1));
    assert_eq!(h.interlace, Interlace::BottomFieldFirst);
    assert_eq!(h.aspect, (16, 15));
    assert_eq!(h.colorspace, Chroma::C420Mpeg2);
    assert_eq!(h.extra, ["YSCSS=420MPEG2", "COLORRANGE=LIMITED"]);
    assert_eq!(h.range_hint(), Some(Range::Limited));
    assert_eq!(h.to_line(), line);
    assert_eq!(h.frame_bytes(), 622_080);

    // Defaults: C420jpeg, unknown rate and aspect, progressive; unknown fields ignored.
    let h = Y4mHeader::parse(b"YUV4MPEG2 H2 W4 Zwhatever").unwrap();
    assert_eq!(h.colorspace, Chroma::C420Jpeg);
    assert_eq!((h.fps, h.aspect), ((0, 0), (0, 0)));
    assert_eq!(h.interlace, Interlace::Progressive);
    assert_eq!(h.to_line(), "YUV4MPEG2 W4 H2 F0:0 Ip A0:0 C420jpeg\n");

    let h = Y4mHeader::parse(b"YUV4MPEG2 W1920 H1080 F30000:1001 It A1:1 C444 XCOLORRANGE=FULL")
        .unwrap();
    assert_eq!(h.fps, (30000, 1001));
    assert_eq!(h.interlace, Interlace::TopFieldFirst);
    assert!(h.interlace.is_interlaced());
    assert_eq!(h.range_hint(), Some(Range::Full));
    let c = YuvConversion::for_header(&h);
    assert_eq!((c.matrix, c.range), (Matrix::Bt709, Range::Full));
    let sd = Y4mHeader::parse(b"YUV4MPEG2 W720 H480").unwrap();
    let c = YuvConversion::for_header(&sd);
    assert_eq!((c.matrix, c.range), (Matrix::Bt601, Range::Limited));
}

#[test]
fn interlacing_is_reported() {
    for (code, want) in [
        ('p', Interlace::Progressive),
        ('t', Interlace::TopFieldFirst),
        ('b', Interlace::BottomFieldFirst),
        ('m', Interlace::Mixed),
        ('?', Interlace::Unknown),
    ] {
        let bytes = format!("YUV4MPEG2 W8 H8 F25:1 I{code}\n").into_bytes();
        let r = Y4mReader::new(Cursor::new(bytes), "t").unwrap();
        assert_eq!(r.header().interlace, want);
        assert_eq!(want.code(), code);
    }
    let e = read_err(b"YUV4MPEG2 W8 H8 Ix\n".to_vec());
    assert!(e.to_string().contains("invalid interlacing `Ix`"), "{e}");
}

#[test]
fn malformed_headers_are_rejected_cleanly() {
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (b"YUV4MPEG2 H576 F25:1\n".to_vec(), "missing W (width)"),
        (b"YUV4MPEG2 W720 F25:1\n".to_vec(), "missing H (height)"),
        (
            b"YUV4MPEG2 W0 H576\n".to_vec(),
            "width 0 is out of range (1 to 16384)",
        ),
        (
            b"YUV4MPEG2 W99999999 H576\n".to_vec(),
            "width 99999999 is out of range",
        ),
        (
            b"YUV4MPEG2 W99999999999999999999999 H576\n".to_vec(),
            "out of range",
        ),
        (
            b"YUV4MPEG2 W720 H16385\n".to_vec(),
            "height 16385 is out of range",
        ),
        (b"YUV4MPEG2 W-5 H576\n".to_vec(), "invalid width `W-5`"),
        (b"YUV4MPEG2 Wx H576\n".to_vec(), "invalid width `Wx`"),
        (
            b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR".to_vec(),
            "not a YUV4MPEG2 stream (it starts with \"\\x89PNG",
        ),
        (b"YUV4MPEG W720 H576\n".to_vec(), "not a YUV4MPEG2 stream"),
        (b"YUV4MPEG2W720 H576\n".to_vec(), "not a YUV4MPEG2 stream"),
        (b"".to_vec(), "the stream is empty"),
        (
            b"YUV4MPEG2 W720 H576".to_vec(),
            "ends inside the header line",
        ),
        (
            [b"YUV4MPEG2 ".as_slice(), &[b'X'; 5000]].concat(),
            "longer than 4096 bytes",
        ),
        (
            b"YUV4MPEG2 W720 H576 C420p11\n".to_vec(),
            "unsupported colour space `C420p11`",
        ),
        (
            b"YUV4MPEG2 W720 H576 C444alpha\n".to_vec(),
            "unsupported colour space",
        ),
        (
            b"YUV4MPEG2 W720 H576 F30:0\n".to_vec(),
            "invalid frame rate `F30:0`",
        ),
        (
            b"YUV4MPEG2 W720 H576 F30\n".to_vec(),
            "invalid frame rate `F30`",
        ),
        (
            b"YUV4MPEG2 W720 H576 A1:x\n".to_vec(),
            "invalid pixel aspect ratio",
        ),
        (b"YUV4MPEG2 W720 H576 \xff\n".to_vec(), "not text"),
    ];
    for (bytes, want) in cases {
        let e = read_err(bytes.clone());
        let msg = e.to_string();
        assert!(
            msg.starts_with("stdin: y4m header: ") && msg.contains(want),
            "{:?}: {msg}",
            String::from_utf8_lossy(&bytes)
        );
        let io: IoError = e.into();
        assert!(io.is_input_error(), "{io}");
        assert_eq!(io.path(), Path::new("stdin"));
    }
}

// ---------------------------------------------------------------------------------------
