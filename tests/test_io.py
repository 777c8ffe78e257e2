"""File formats: exact round trips, foreign layouts, real recordings and every way a file can be bad."""
import os
import struct

import h5py
import numpy as np
import pytest
import scipy.io as sio

import vibmeasure as vm


@pytest.fixture
def rec2(rng):
    d = rng.normal(size=(2, 500))
    return vm.Record(d, fs=512.0, channels=[vm.Channel("hammer", "force", "N"),
                                            vm.Channel("acc1", "acceleration", "m/s^2", "tip")],
                     t0=0.25, meta={"operator": "test"}, history=("from_array",))


# --- CSV --------------------------------------------------------------------------------------
def test_csv_round_trip_keeps_values_units_and_fs(tmp_path, rec2):
    p = vm.write(tmp_path / "r.csv", rec2)
    back = vm.read(p)
    np.testing.assert_array_equal(back.data, rec2.data)  # %.17g text: exact doubles
    assert back.fs == rec2.fs and back.t0 == rec2.t0
    assert [(c.name, c.quantity, c.unit) for c in back.channels] == [("hammer", "force", "N"),
                                                                      ("acc1", "acceleration", "m/s^2")]


def test_csv_time_column_semicolon_decimal_comma(tmp_path):
    t = np.arange(6) * 0.001
    rows = ["Zeit [s];Beschl [g]"] + [f"{a:.3f};{b:.4f}".replace(".", ",") for a, b in zip(t, np.sin(t * 900))]
    p = tmp_path / "de.csv"
    p.write_text("\n".join(rows) + "\n")
    r = vm.read(p)
    assert r.fs == pytest.approx(1000.0, rel=1e-9)
    assert r.channels[0].unit == "g" and r.channels[0].quantity == "acceleration"
    np.testing.assert_allclose(r.data[0], np.round(np.sin(t * 900), 4), atol=1e-12)


def test_csv_tab_and_fs_header(tmp_path):
    p = tmp_path / "tab.csv"
    p.write_text("# fs = 2048\na\tb\n1\t2\n3\t4\n5\t6\n")
    r = vm.read(p)
    assert r.fs == 2048.0 and r.names == ["a", "b"]
    np.testing.assert_array_equal(r.data, [[1, 3, 5], [2, 4, 6]])


def test_csv_without_timing_needs_fs(tmp_path):
    p = tmp_path / "bare.csv"
    p.write_text("1.0\n2.0\n3.0\n")
    with pytest.raises(vm.ParameterError, match="fs .sampling rate in Hz. is required"):
        vm.read(p)
    assert vm.read(p, fs=100.0).fs == 100.0


def test_csv_non_uniform_time_column(tmp_path):
    p = tmp_path / "jitter.csv"
    p.write_text("time,x\n0,1\n0.001,2\n0.002,3\n0.0035,4\n0.0045,5\n")
    with pytest.raises(vm.ParameterError, match="not uniformly sampled.*row 3"):
        vm.read(p)


def test_csv_truncated_and_garbage(tmp_path):
    p = tmp_path / "trunc.csv"
    p.write_text("time,a,b\n0,1,2\n0.1,3,4\n0.2,5")   # a last line with a field missing: dropped, said so
    with pytest.warns(vm.QualityWarning, match="no end of line"):
        assert vm.read(p).n_samples == 2
    p.write_text("time,a,b\n0,1,2\n0.1,3,4\n0.2,5\n")   # a short last row with its end of line: refused
    with pytest.raises(vm.ParameterError, match="truncated"):
        vm.read(p)
    g = tmp_path / "text.csv"
    g.write_text("time,a\n0,1\n0.1,abc\n")
    with pytest.raises(vm.ParameterError, match="non-numeric"):
        vm.read(g)


def test_csv_fs_contradiction(tmp_path, rec2):
    p = vm.write(tmp_path / "r.csv", rec2)
    with pytest.raises(vm.ParameterError, match="contradicts"):
        vm.read(p, fs=1000.0)


def test_csv_channel_selection(tmp_path, rec2):
    p = vm.write(tmp_path / "r.csv", rec2)
    assert vm.read(p, channels=["acc1"]).names == ["acc1"]
    with pytest.raises(vm.ParameterError, match="'acc9' is not in"):
        vm.read(p, channels=["acc9"])


# --- HDF5 -------------------------------------------------------------------------------------
def test_hdf5_round_trip_exact_with_schema(tmp_path, rec2):
    p = vm.write(tmp_path / "r.h5", rec2)
    assert vm.read(p) == rec2  # data, fs, t0, channels, meta and history all equal
    with h5py.File(p) as f:
        assert f.attrs["vibmeasure_schema"] == "vibmeasure.record"
        assert int(f.attrs["schema_version"]) == 2
    assert open(p, "rb").read(23) == b"VIBMEASURE-SEAL-SHA256 "  # sealed: SHA-256 in the user block


def test_hdf5_bare_dataset_needs_fs(tmp_path):
    p = tmp_path / "bare.h5"
    with h5py.File(p, "w") as f:
        f["grp/acc"] = np.arange(8.0)
    with pytest.raises(vm.ParameterError, match="fs .sampling rate in Hz. is required"):
        vm.read(p, dataset="grp/acc")
    r = vm.read(p, dataset="grp/acc", fs=50.0, unit="g")
    assert r.names == ["grp.acc"] and r.channels[0].quantity == "acceleration"


def test_hdf5_truncated(tmp_path, rec2):
    p = vm.write(tmp_path / "r.h5", rec2)
    data = p.read_bytes()
    bad = tmp_path / "cut.h5"
    bad.write_bytes(data[: len(data) // 2])
    with pytest.raises(vm.ParameterError, match="unreadable|damaged"):
        vm.read(bad)


def test_hdf5_newer_schema_refused(tmp_path, rec2):
    p = vm.write(tmp_path / "r.h5", rec2)
    with h5py.File(p, "a") as f:
        f.attrs["schema_version"] = 99
    with pytest.raises(vm.ParameterError, match="does not match the SHA-256"):
        vm.read(p)  # edited after writing: the seal no longer matches
    from vibmeasure.io.hdf5 import seal
    seal(p)  # as a newer vibmeasure would have written it
    with pytest.raises(vm.ParameterError, match="schema_version 99"):
        vm.read(p)


# --- WAV --------------------------------------------------------------------------------------
def test_wav_float_round_trip(tmp_path, rec2):
    p = vm.write(tmp_path / "r.wav", rec2)
    back = vm.read(p)
    np.testing.assert_array_equal(back.data, rec2.data)
    assert back.fs == 512.0


def test_wav_int16_full_scale(tmp_path):
    from scipy.io import wavfile
    p = tmp_path / "i16.wav"
    wavfile.write(p, 8000, np.array([0, 16384, -32768, 32767], dtype=np.int16))
    r = vm.read(p)
    np.testing.assert_array_equal(r.data[0], [0, 0.5, -1.0, 32767 / 32768])
    assert r.meta["wav_dtype"] == "int16"


def test_wav_truncated(tmp_path, rec2):
    p = vm.write(tmp_path / "r.wav", rec2)
    bad = tmp_path / "cut.wav"
    bad.write_bytes(p.read_bytes()[:30])
    with pytest.raises(vm.ParameterError, match="unreadable"):
        vm.read(bad)


def test_wav_non_integer_fs_refused(tmp_path):
    r = vm.Record.from_array(np.zeros(4), fs=100.5)
    with pytest.raises(vm.ParameterError, match="integer sampling rate"):
        vm.write(tmp_path / "x.wav", r)
    assert not list(tmp_path.iterdir())  # nothing half-written


# --- MAT --------------------------------------------------------------------------------------
def test_mat_v5_nested_struct_fields(tmp_path):
    p = tmp_path / "s.mat"
    gs = np.sin(np.arange(100) / 5.0)
    sio.savemat(p, {"bearing": {"gs": gs[:, None], "sr": 2000.0, "rate": 25.0}, "other": np.ones((3, 3))})
    r = vm.read(p, channels=["bearing.gs"])
    assert r.names == ["bearing.gs"] and r.fs == 2000.0
    np.testing.assert_array_equal(r.data[0], gs)


def test_mat_time_vector_and_matrix_rows(tmp_path):
    p = tmp_path / "m.mat"
    acc = np.vstack([np.arange(50.0), -np.arange(50.0)])
    sio.savemat(p, {"Fe": {"Out": {"Acc": acc, "Time": (np.arange(50) / 256.0)[None, :]}}})
    r = vm.read(p)
    assert r.names == ["Fe.Out.Acc[0]", "Fe.Out.Acc[1]"] and r.fs == pytest.approx(256.0, rel=1e-12)
    assert vm.read(p, channels=["Fe.Out.Acc[1]"]).data[0, 3] == -3.0


def test_mat_v73_through_h5py(tmp_path):
    # MATLAB v7.3 files are HDF5 with a 512-byte user block; arrays are stored transposed
    p = tmp_path / "v73.mat"
    x = np.cos(np.arange(64) / 3.0)
    with h5py.File(p, "w", userblock_size=512) as f:
        f.create_dataset("sig", data=x[None, :].T.T)  # MATLAB column vector (64x1) is (1, 64) in HDF5
        f.create_dataset("fs", data=np.array([[1000.0]]))
        f["sig"].attrs["MATLAB_class"] = np.bytes_("double")
    with open(p, "r+b") as fh:
        fh.write(b"MATLAB 7.3 MAT-file".ljust(116, b" ") + struct.pack("<8x") + b"\x00\x02IM")
    r = vm.read(p)
    assert r.fs == 1000.0
    np.testing.assert_array_equal(r.data[0], x)


def test_mat_without_timing_and_truncated(tmp_path):
    p = tmp_path / "n.mat"
    sio.savemat(p, {"x": np.arange(10.0)})
    with pytest.raises(vm.ParameterError, match="fs .sampling rate in Hz. is required"):
        vm.read(p)
    bad = tmp_path / "cut.mat"
    bad.write_bytes(p.read_bytes()[:150])
    with pytest.raises(vm.ParameterError, match="unreadable|truncated"):
        vm.read(bad)


# --- LVM --------------------------------------------------------------------------------------
LVM = """LabVIEW Measurement\t
Writer_Version\t2
Reader_Version\t2
Separator\tTab
Decimal_Separator\t.
Multi_Headings\tNo
X_Columns\tOne
Time_Pref\tRelative
***End_of_Header***\t

Channels\t2\t
Samples\t4\t4\t
Y_Unit_Label\tg\tg\t
X_Dimension\tTime\tTime\t
X0\t0.0\t0.0\t
Delta_X\t0.0005\t0.0005\t
***End_of_Header***\t\t
X_Value\tacc_a\tacc_b\tComment
0.0\t1.5\t-1.5
0.0005\t2.5\t-2.5
0.001\t3.5\t-3.5
0.0015\t4.5\t-4.5
"""


def test_lvm_with_header(tmp_path):
    p = tmp_path / "h.lvm"
    p.write_text(LVM)
    r = vm.read(p)
    assert r.fs == pytest.approx(2000.0) and r.names == ["acc_a", "acc_b"]
    assert r.channels[0].unit == "g"
    np.testing.assert_array_equal(r.data[1], [-1.5, -2.5, -3.5, -4.5])


def test_lvm_truncated_header(tmp_path):
    p = tmp_path / "t.lvm"
    p.write_text(LVM.split("Channels")[0])
    with pytest.raises(vm.ParameterError, match="header is incomplete"):
        vm.read(p)


# --- dispatch and writing ---------------------------------------------------------------------
def test_mat_struct_arrays_by_element_name_or_index(tmp_path):
    # the Paderborn rig's files hold struct arrays Y(1..7) with fields Name and Data, at several rates:
    # each element's fields are reached by its Name (Y.vibration_1.Data); without distinct names, by
    # its 1-based index (S(2).Data). With no channel named, the dominant length is taken
    import scipy.io as sio
    rng = np.random.default_rng(5)
    dt = [("Name", "O"), ("Raster", "O"), ("Data", "O")]
    Y = np.zeros((1, 4), dtype=dt)
    for i, (name, n) in enumerate([("phase_current_1", 640), ("phase_current_2", 640), ("vibration_1", 640),
                                   ("temp_2_bearing_module", 1)]):
        Y[0, i] = (name, "HostService", rng.normal(size=(1, n)))
    S = np.zeros((1, 2), dtype=[("Name", "O"), ("Data", "O")])
    S[0, 0], S[0, 1] = ("a", rng.normal(size=(1, 64))), ("a", rng.normal(size=(1, 64)))   # names not distinct
    top = np.zeros((1, 1), dtype=[("Info", "O"), ("Y", "O"), ("S", "O")])
    top[0, 0] = ("", Y, S)
    f = tmp_path / "N15_M07_F10_K001_1.mat"
    sio.savemat(f, {"N15": top})
    rec = vm.read(f, fs=64000)
    assert rec.names == ["N15.Y.phase_current_1.Data", "N15.Y.phase_current_2.Data", "N15.Y.vibration_1.Data"]
    vib = vm.read(f, fs=64000, channels=["N15.Y.vibration_1.Data"])
    np.testing.assert_array_equal(vib.data[0], Y[0, 2]["Data"].ravel())
    np.testing.assert_array_equal(vm.read(f, fs=1000, channels="N15.S(2).Data").data[0], S[0, 1]["Data"].ravel())


def test_mat_v73_struct_arrays_by_element_name_or_index(tmp_path):
    # the same layout saved as MATLAB v7.3 (HDF5): a struct array's fields are datasets of references,
    # one per element, stored transposed, to values in #refs# (chars as UTF-16 codes); a cell field
    # holds references too and is no signal
    rng = np.random.default_rng(6)
    p = tmp_path / "v73_struct.mat"
    values = {}
    with h5py.File(p, "w", userblock_size=512) as f:
        refs = f.create_group("#refs#")

        def put(arr, cls):
            d = refs.create_dataset(f"r{len(refs)}", data=arr)
            d.attrs["MATLAB_class"] = np.bytes_(cls)
            return d.ref

        def text(t):
            return put(np.array([[ord(c)] for c in t], dtype=np.uint16), "char")

        def struct_array(group, names, data):
            group.attrs["MATLAB_class"] = np.bytes_("struct")
            group.create_dataset("Name", data=np.array([[text(t)] for t in names], dtype=h5py.ref_dtype))
            group.create_dataset("Data", data=np.array([[put(x[:, None], "double")] for x in data],
                                                       dtype=h5py.ref_dtype))
            c = group.create_dataset("Note", data=np.array([[text("x")] for _ in names], dtype=h5py.ref_dtype))
            c.attrs["MATLAB_class"] = np.bytes_("cell")

        top = f.create_group("N15")
        top.attrs["MATLAB_class"] = np.bytes_("struct")
        values["Y"] = [rng.normal(size=640) for _ in range(3)]
        struct_array(top.create_group("Y"), ["phase_current_1", "vibration_1", "force"], values["Y"])
        values["S"] = [rng.normal(size=64) for _ in range(2)]
        struct_array(top.create_group("S"), ["a", "a"], values["S"])     # names not distinct: by index
        top.create_dataset("fs", data=np.array([[64000.0]]))
    with open(p, "r+b") as fh:
        fh.write(b"MATLAB 7.3 MAT-file".ljust(116, b" ") + struct.pack("<8x") + b"\x00\x02IM")
    rec = vm.read(p)
    assert rec.fs == 64000.0
    assert rec.names == ["N15.Y.phase_current_1.Data", "N15.Y.vibration_1.Data", "N15.Y.force.Data"]
    np.testing.assert_array_equal(vm.read(p, channels=["N15.Y.vibration_1.Data"]).data[0], values["Y"][1])
    np.testing.assert_array_equal(vm.read(p, channels="N15.S(2).Data").data[0], values["S"][1])
    # a hostile file whose struct array refers back to itself: the named error, not a recursion
    q = tmp_path / "cycle.mat"
    with h5py.File(q, "w", userblock_size=512) as f:
        g = f.create_group("S")
        g.attrs["MATLAB_class"] = np.bytes_("struct")
        g.create_dataset("Data", data=np.array([[g.ref], [g.ref]], dtype=h5py.ref_dtype))
        f.create_dataset("fs", data=np.array([[1000.0]]))
    with open(q, "r+b") as fh:
        fh.write(b"MATLAB 7.3 MAT-file".ljust(116, b" ") + struct.pack("<8x") + b"\x00\x02IM")
    with pytest.raises(vm.ParameterError, match="refers back to itself"):
        vm.read(q)


def test_a_file_named_by_its_time_stamp_is_read_by_its_content(tmp_path):
    # the IMS rig names its files by time stamp (2004.02.12.10.32.39: the "ending" is .39) and writes
    # tab-separated columns without a header: the content decides the format
    rng = np.random.default_rng(3)
    x = np.round(rng.normal(size=(2048, 4)), 3)
    ims = tmp_path / "2004.02.12.10.32.39"
    np.savetxt(ims, x, fmt="%.3f", delimiter="\t")
    rec = vm.read(ims, fs=20480)
    assert rec.data.shape == (4, 2048) and rec.fs == 20480
    np.testing.assert_allclose(rec.data, x.T, atol=5e-4)   # 3 decimals written
    # a short file (under the 4 kB looked at) keeps its last line: two rows are enough
    (tmp_path / "2004.02.12.10.52.39").write_text("0.5\t1.5\n-0.25\t2.0\n")
    np.testing.assert_array_equal(vm.read(tmp_path / "2004.02.12.10.52.39", fs=10).data, [[0.5, -0.25], [1.5, 2.0]])
    # binary formats by their signatures, whatever the name
    src = vm.Record.from_array(x.T, fs=1000.0, unit="g")
    for ending in (".h5", ".wav"):
        f = vm.write(tmp_path / f"r{ending}", src)
        bare = tmp_path / f"bare{ending.replace('.', '_')}.dat"
        bare.write_bytes(f.read_bytes())
        back = vm.read(bare)
        assert back.data.shape == (4, 2048)
    import scipy.io as sio
    sio.savemat(tmp_path / "m.mat", {"acc": x[:, 0], "fs": 1000.0})
    (tmp_path / "m.dat").write_bytes((tmp_path / "m.mat").read_bytes())
    np.testing.assert_allclose(vm.read(tmp_path / "m.dat", channels=["acc"]).data[0], x[:, 0])
    # damaged content under such a name keeps its named errors: a NaN row, a cut HDF5 file
    (tmp_path / "2004.02.12.10.42.39").write_text("1.0\t2.0\nnan\t3.0\n4\t5\n")
    with pytest.raises(vm.ParameterError, match="row 2 has missing values"):
        vm.read(tmp_path / "2004.02.12.10.42.39", fs=100)
    (tmp_path / "cut.39").write_bytes((tmp_path / "r.h5").read_bytes()[:1500])
    with pytest.raises(vm.ParameterError, match="damaged|truncated|not a valid"):
        vm.read(tmp_path / "cut.39")
    # neither a known signature nor delimited numbers: a clear error naming the readable formats
    (tmp_path / "junk.bin").write_bytes(bytes(range(256)) * 8)
    (tmp_path / "words.log").write_text("pump 3 started\nno data here\nend\n")
    for bad in ("junk.bin", "words.log"):
        with pytest.raises(vm.ParameterError, match="unknown file type .* none of the readable formats"):
            vm.read(tmp_path / bad)


def test_unknown_missing_empty(tmp_path):
    with pytest.raises(vm.ParameterError, match="does not exist"):
        vm.read(tmp_path / "nope.csv")
    (tmp_path / "x.xyz").write_text("1")
    with pytest.raises(vm.ParameterError, match="unknown file type"):
        vm.read(tmp_path / "x.xyz")
    (tmp_path / "e.csv").write_text("")
    with pytest.raises(vm.ParameterError, match="empty"):
        vm.read(tmp_path / "e.csv")


def test_failed_write_leaves_nothing(tmp_path, rec2, monkeypatch):
    def boom(*a, **k):
        raise OSError("disk full")
    monkeypatch.setattr(h5py.File, "create_dataset", boom)
    with pytest.raises(OSError):
        vm.write(tmp_path / "r.h5", rec2)
    assert os.listdir(tmp_path) == []


# --- real recordings (../shared/data) ---------------------------------------------------------
def test_real_cwru_mat_needs_fs_and_keeps_rpm(shared_data):
    p = shared_data("cwru/IR007_0.mat")
    with pytest.raises(vm.ParameterError, match="fs .sampling rate in Hz. is required"):
        vm.read(p)
    r = vm.read(p, fs=12000, unit="g", channels=["X105_DE_time"])
    assert r.n_samples == 121265 and r.meta["rpm"] == 1797.0
    assert r.channels[0].quantity == "acceleration"


def test_real_case1_fs_from_file(shared_data):
    r = vm.read(shared_data("impact/case1.mat"))
    assert r.names == ["Time_chan_1", "Time_chan_2"]  # the frequency-domain arrays are not time channels
    assert r.fs == 1280.0 and r.n_samples == 4096


def test_real_dexpilab_struct(shared_data):
    r = vm.read(shared_data("ringdown/dexpilab1_VDeXpiLab1_Exp.mat"), channels=["Al.Out.Acc"])
    assert r.names == ["Al.Out.Acc[0]", "Al.Out.Acc[1]"]
    assert r.fs == pytest.approx(2048.0, rel=1e-9) and r.n_samples == 40960


def test_real_lvm_headerless_and_spectrum(shared_data):
    p = shared_data("ringdown/NIMT_lab1_DanHendata_009.lvm")
    with pytest.raises(vm.ParameterError, match="fs .sampling rate in Hz. is required"):
        vm.read(p)
    assert vm.read(p, fs=10000).n_samples == 250000
    with pytest.raises(vm.ParameterError, match="holds a spectrum"):
        vm.read(shared_data("frf/Chowdhury_beam_impulse_FFT_data.lvm"))


# --- UFF ------------------------------------------------------------------------------------------
def test_uff_ascii_and_binary_agree(shared_data):
    a = vm.read(shared_data("uff/Sample_UFF58_ascii.uff"))
    b = vm.read(shared_data("uff/Sample_UFF58b_bin.uff"))
    assert a.fs == b.fs == pytest.approx(65536.0, rel=1e-5) and a.n_samples == b.n_samples == 79292
    # the ASCII file keeps 6 significant digits of the binary values: 5e-6 relative
    np.testing.assert_allclose(a.data, b.data, rtol=5e-6, atol=1e-9 * np.abs(b.data).max())


def test_uff_multichannel_acceleration(shared_data):
    r = vm.read(shared_data("uff/MPSTD_Set001_2024_10_08.uff"))
    assert r.n_channels == 4 and r.fs == pytest.approx(3200.0) and r.duration == pytest.approx(69.5)
    assert r.channels[0].quantity == "acceleration" and r.channels[0].unit == "m/s^2"
    spec = vm.psd(r, nperseg=8192, channels=[1])
    p = vm.pick_peaks(spec, band=(170, 195), n=4)
    # output-only record: spectral peaks near 181.6 and 184.8 Hz (shared/data README; 0.39 Hz lines)
    for f0 in (181.6, 184.8):
        assert np.min(np.abs(p.freq - f0)) < 0.2


def test_uff_truncated(tmp_path, shared_data):
    src = shared_data("uff/Sample_UFF58_ascii.uff").read_bytes()
    bad = tmp_path / "cut.uff"
    bad.write_bytes(src[: len(src) // 3])
    with pytest.raises(vm.ParameterError, match="unreadable|truncated|no dataset 58|differ"):
        vm.read(bad)


def test_whitespace_separated_columns_are_read(tmp_path):
    """Loggers and OMA datasets write numbers in columns separated by runs of spaces (.asc, .txt): read
    exactly, with or without a header and leading spaces; ``delimiter=`` forces a separator, and a
    wrong one is named."""
    (tmp_path / "log.asc").write_text("acc1 acc2 acc3\n 0.125  -1.5e-3   7\n 0.250   2.0e-3  -8\n-0.375   1.0e-3   9\n")
    rec = vm.read(tmp_path / "log.asc", fs=100.0)
    assert rec.names == ["acc1", "acc2", "acc3"]
    np.testing.assert_array_equal(rec.data[1], [-1.5e-3, 2.0e-3, 1.0e-3])
    (tmp_path / "plain.txt").write_text("  1.5   2.5\n  3.5   4.5\n  5.5   6.5\n")
    rec = vm.read(tmp_path / "plain.txt", fs=10.0)
    np.testing.assert_array_equal(rec.data, [[1.5, 3.5, 5.5], [2.5, 4.5, 6.5]])
    (tmp_path / "comma.txt").write_text("1,5  2,5\n3,5  4,5\n")     # decimal comma between spaces
    np.testing.assert_array_equal(vm.read(tmp_path / "comma.txt", fs=10.0).data, [[1.5, 3.5], [2.5, 4.5]])
    (tmp_path / "semi.txt").write_text("1.5;2.5\n3.5;4.5\n")
    assert vm.read(tmp_path / "semi.txt", fs=10.0, delimiter=";").n_channels == 2
    with pytest.raises(vm.ParameterError, match="delimiter='[|]' must be one of"):
        vm.read(tmp_path / "plain.txt", fs=10.0, delimiter="|")
    vm.write(tmp_path / "r.h5", rec)
    with pytest.raises(vm.ParameterError, match="applies to text files"):
        vm.read(tmp_path / "r.h5", delimiter=",")


def test_a_24_bit_pcm_wav_reads_at_full_scale(tmp_path):
    """Measurement recorders write 24-bit PCM, which cannot be memory-mapped: it is read (its size bounded
    by the file's first) and scaled to full scale 1.0, sample for sample (oracle: the integers written)."""
    import struct
    n, fs = 1000, 48000
    ints = (np.sin(2 * np.pi * 1000 * np.arange(n) / fs) * (2 ** 23 - 1)).astype(np.int32)
    ints[0], ints[1] = -(2 ** 23), 2 ** 23 - 1
    frames = b"".join(int(v).to_bytes(4, "little", signed=True)[:3] for v in ints)
    fmt = struct.pack("<HHIIHH", 1, 1, fs, fs * 3, 3, 24)
    body = b"WAVE" + b"fmt " + struct.pack("<I", len(fmt)) + fmt + b"data" + struct.pack("<I", len(frames)) + frames
    p = tmp_path / "rec24.wav"
    p.write_bytes(b"RIFF" + struct.pack("<I", len(body)) + body)
    r = vm.read(p)
    assert r.fs == fs and r.n_samples == n
    np.testing.assert_array_equal(r.data[0], ints / 2.0 ** 23)   # exact: 24-bit integers over 2^23


def test_a_mat_file_that_inflates_past_the_limit_is_refused_before_it_is_decompressed(tmp_path):
    """Issue 48: a struct field is not in whosmat; its inflated size is read from the compressed element's
    own tag. 160 MB of zeros compress to 156 kB."""
    import scipy.io as sio
    p = tmp_path / "bomb.mat"
    sio.savemat(p, {"s": {"big": np.zeros((1, 20_000_000)), "fs": 1000.0}}, do_compression=True)
    assert p.stat().st_size < 200_000
    with pytest.raises(vm.ParameterError, match="decompressed, declares 20,000,0"):
        vm.read(p, max_samples=1_000_000)


def _wav_bytes(bits, n_data, channels=1, rate=1000):
    import struct
    align = channels * max(bits, 8) // 8
    fmt = struct.pack("<HHIIHH", 1, channels, rate, rate * align, align, bits)
    body = b"WAVE" + b"fmt " + struct.pack("<I", 16) + fmt + b"data" + struct.pack("<I", n_data) + b"\0" * n_data
    return b"RIFF" + struct.pack("<I", len(body)) + body


@pytest.mark.parametrize("bits,n_data,rule", [(0, 200, "0 bits per sample"), (12, 200, "12 bits per sample"),
                                              (16, 0, "0 sample"), (16, 2, "1 sample")])
def test_crafted_wav_headers_are_named(tmp_path, bits, n_data, rule):
    """Issue 48: a WAV with 0 bits per sample or an empty data chunk was read as a record."""
    p = tmp_path / "x.wav"
    p.write_bytes(_wav_bytes(bits, n_data))
    with pytest.raises(vm.ParameterError, match=rule):
        vm.read(p)


def test_a_mat_sampling_rate_that_is_a_logical_is_refused(tmp_path):
    import scipy.io as sio
    p = tmp_path / "x.mat"
    sio.savemat(p, {"x": np.random.default_rng(0).normal(size=(1, 1000)), "fs": np.array([[True]])})
    with pytest.raises(vm.ParameterError, match="fs = True is a boolean"):
        vm.read(p)


def _frf_case(tmp_path, **variables):
    import scipy.io as sio
    p = tmp_path / "frf.mat"
    sio.savemat(p, variables)
    return p


def test_read_frf_of_a_mat_checks_what_an_frf_is(tmp_path):
    """Issue 48: a real FRF, a frequency with NaN, and a 2-D FRF (read as outputs, not flattened)."""
    f = np.linspace(1, 100, 100)
    H = 1 / (1000 - (2 * np.pi * f) ** 2 + 2j * np.pi * f * 2)
    two = vm.read_frf(_frf_case(tmp_path, H=np.vstack([H, 2 * H]).T, freq=f), variable="H")
    assert two.h.shape == (2, 1, 100)
    np.testing.assert_allclose(two.h[1, 0], 2 * H)           # the second output, not the first's tail
    with pytest.raises(vm.ParameterError, match="is real"):
        vm.read_frf(_frf_case(tmp_path, H=np.abs(H), freq=f), variable="H")
    with pytest.raises(vm.ParameterError, match="finite and increasing"):
        vm.read_frf(_frf_case(tmp_path, H=H, freq=np.r_[f[:-1], np.nan]), variable="H")
    with pytest.raises(vm.ParameterError, match="finite and increasing"):
        vm.read_frf(_frf_case(tmp_path, H=H, freq=f[::-1]), variable="H")


def test_a_two_output_uff_cut_after_its_second_opening_line_is_named(tmp_path):
    """Issue 48: a file cut right after a dataset's opening -1 line ends with -1 too; it was read as one
    output."""
    import pyuff
    f = np.linspace(1, 100, 64)
    p = tmp_path / "two.uff"
    u = pyuff.UFF(str(p))
    for k in (1, 2):
        u.write_sets(pyuff.prepare_58(func_type=4, rsp_node=k, rsp_dir=3, ref_node=1, ref_dir=3, binary=0,
                                      data=(k / (1000 - (2 * np.pi * f) ** 2 + 1j * f)).astype(complex), x=f,
                                      id1=f"out{k}", rsp_ent_name=f"out{k}", ref_ent_name="force",
                                      abscissa_spacing=1, ordinate_spec_data_type=8, orddenom_spec_data_type=13,
                                      abscissa_spec_data_type=18), mode="add")
    assert vm.read_frf(p).h.shape[0] == 2
    raw = p.read_bytes()
    second = raw.index(b"    -1", raw.index(b"    -1", raw.index(b"    -1") + 6) + 6)   # the 2nd dataset's opening
    p.write_bytes(raw[:second + 7])
    with pytest.raises(vm.ParameterError, match="odd number"):
        vm.read_frf(p)


def test_a_mat_header_with_a_negative_dimension_is_named(tmp_path):
    import struct

    import scipy.io as sio
    p = tmp_path / "neg.mat"
    sio.savemat(p, {"x": np.arange(12.0).reshape(3, 4), "fs": 100.0}, do_compression=False)
    raw = bytearray(p.read_bytes())
    i = raw.find(struct.pack("<IIii", 5, 8, 3, 4))      # the dims sub-element: int32 x 2
    raw[i + 8:i + 12] = struct.pack("<i", -3)
    p.write_bytes(bytes(raw))
    with pytest.raises(vm.ParameterError, match="dimension below 0"):
        vm.read(p)


@pytest.mark.parametrize("col,fs", [("time_ms", 1000.0), ("t_us", 1e6), ("time_s", 1.0), ("Time", 1.0)])
def test_a_time_column_with_its_unit_in_the_name(tmp_path, col, fs):
    """Issue 49: a time_ms column was read as a channel."""
    p = tmp_path / "t.csv"
    p.write_text(f"{col},acc\n0,0.1\n1,0.2\n2,0.3\n3,0.1\n")
    r = vm.read(p)
    assert r.names == ["acc"] and r.fs == pytest.approx(fs)
