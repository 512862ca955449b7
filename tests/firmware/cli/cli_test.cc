// `refocus run` as a user meets it: every bad input gives one line on stderr that names the file
// and the problem, a non-zero exit, and nothing under the output name (nor a stray temporary).
#include <dirent.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "firmware/codecs/exif.h"
#include "firmware/codecs/jpeg_writer.h"
#include "tests/algo/motion/burst.h"
#include "tests/firmware/cli/cli_fixture.h"
#include "tests/firmware/codecs/test_images.h"

namespace lb {
namespace {

using clitest::Cli;
using clitest::Result;
using clitest::Slurp;
using test::Bytes;

// A valid 64x48 RGB PNG of one grey, for tests that break one of its chunks.
Bytes GreyPng() {
  test::PngSpec spec;
  spec.width = 64;
  spec.height = 48;
  spec.rows.resize(64 * 48 * 3, 90);
  Bytes png;
  return test::EncodePng(spec, &png) ? png : Bytes{};
}

TEST_F(Cli, SyntheticRunWritesAJpegOfTheConfiguredSize) {
  Result r = Run({"run", "--synthetic", "--size", "200x150", "--labels", "16", "--out", Out()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find(Out()), std::string::npos) << r.out;
  const std::string jpeg = Slurp(Out());
  ASSERT_GT(jpeg.size(), 1000u);
  EXPECT_EQ(static_cast<uint8_t>(jpeg[0]), 0xFF);
  EXPECT_EQ(static_cast<uint8_t>(jpeg[1]), 0xD8);
  // SOF0 carries the size: height then width, big-endian.
  const size_t sof = jpeg.find("\xFF\xC0");
  ASSERT_NE(sof, std::string::npos);
  EXPECT_EQ((static_cast<uint8_t>(jpeg[sof + 5]) << 8) | static_cast<uint8_t>(jpeg[sof + 6]), 150);
  EXPECT_EQ((static_cast<uint8_t>(jpeg[sof + 7]) << 8) | static_cast<uint8_t>(jpeg[sof + 8]), 200);
}

TEST_F(Cli, FileBurstRuns) {
  std::vector<std::string> args = {"run",         "--geometry", "rectified", "--labels", "8",
                                   "--disparity", "0,4",        "--out",     Out()};
  for (const auto& p : PpmBurst(3, 64, 48)) args.push_back(p);
  Result r = Run(args);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_GT(Slurp(Out()).size(), 100u);
}

TEST_F(Cli, HandheldSyntheticBurstIsTheDefault) {
  // 640x480: at 320x240 the scene's hand motion gives ~1 px of parallax, the stage's threshold.
  Result r = Run({"run", "--size", "640x480", "--labels", "16", "--out", Out()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "") << "a handheld burst with motion gives depth, not a warning";
  EXPECT_GT(Slurp(Out()).size(), 1000u);
}

TEST_F(Cli, BurstWithoutMotionSavesAnUnblurredPhotoAndSaysWhy) {
  std::vector<std::string> args = {"run", "--labels", "8", "--out", Out()};
  const std::vector<std::string> frame = PpmBurst(1, 160, 120);
  for (int i = 0; i < 5; ++i) args.push_back(frame[0]);  // the camera never moved
  Result r = Run(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("warning"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("not blurred"), std::string::npos) << r.err;
  EXPECT_GT(Slurp(Out()).size(), 1000u);
}

TEST_F(Cli, DepthOfAHandheldBurstFindsItsOwnGeometry) {
  motiontest::Burst b;
  ASSERT_TRUE(motiontest::MakeBurst(motiontest::Handheld(3), 320, 240, 5, &b));
  std::vector<std::string> args = {"depth",           "--labels",      "16",
                                   "--disparity-out", dir_ + "/d.pfm", "--views"};
  for (int v = 0; v < 5; ++v) {
    args.push_back(dir_ + "/h" + std::to_string(v) + ".ppm");
    const std::vector<uint16_t> samples(b.pixels[v].begin(), b.pixels[v].end());
    ASSERT_TRUE(test::WriteFile(args.back(), test::EncodePnm("P6", 320, 240, 255, samples)));
  }
  Result r = Run(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string pfm = Slurp(dir_ + "/d.pfm");
  EXPECT_EQ(pfm.rfind("Pf\n320 240\n", 0), 0u) << pfm.substr(0, 20);
  const size_t header = pfm.find('\n', pfm.find('\n', 3) + 1) + 1;  // "Pf", size, scale lines
  EXPECT_EQ(pfm.size(), header + 320u * 240 * 4) << "header then one float a pixel";

  // The same frame five times: no motion to find, a clear error and no file.
  for (int v = 1; v < 5; ++v) args[6 + v] = args[6];
  args[4] = dir_ + "/still.pfm";
  r = Run(args);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("sideways"), std::string::npos) << r.err;
  EXPECT_EQ(Slurp(dir_ + "/still.pfm"), "");
}

// A converged rig: the wall behind the focus plane at -2 px per view step, a square in front at
// +2. Rectified geometry takes the signed range and the PFM says so.
TEST_F(Cli, RectifiedDepthTakesASignedRange) {
  constexpr int kW = 128, kH = 96;
  auto texture = [](int x, int y, int layer) {
    uint32_t h = static_cast<uint32_t>(x) * 73856093u ^ static_cast<uint32_t>(y) * 19349663u ^
                 static_cast<uint32_t>(layer + 1) * 83492791u;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    return static_cast<uint16_t>(h >> 24);
  };
  auto in_square = [](int x, int y) { return x >= 44 && x < 84 && y >= 28 && y < 68; };
  std::vector<std::string> args = {"depth",         "--geometry", "rectified", "--disparity",
                                   "-3.5,3",        "--labels",   "27",        "--disparity-out",
                                   dir_ + "/d.pfm", "--views"};
  for (int v = 0; v < 5; ++v) {
    const int k = v - 2;
    std::vector<uint16_t> samples(static_cast<size_t>(kW) * kH * 3);
    for (int y = 0; y < kH; ++y) {
      for (int x = 0; x < kW; ++x) {
        // View k shows the reference point that sits at x + k d.
        const bool front = in_square(x + 2 * k, y);
        const int rx = front ? x + 2 * k : x - 2 * k;
        for (int c = 0; c < 3; ++c) samples[(y * kW + x) * 3 + c] = texture(rx, y * 3 + c, front);
      }
    }
    args.push_back(dir_ + "/c" + std::to_string(v) + ".ppm");
    ASSERT_TRUE(test::WriteFile(args.back(), test::EncodePnm("P6", kW, kH, 255, samples)));
  }
  const Result r = Run(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string pfm = Slurp(dir_ + "/d.pfm");
  const size_t header = pfm.find('\n', pfm.find('\n', 3) + 1) + 1;
  ASSERT_EQ(pfm.size(), header + static_cast<size_t>(kW) * kH * 4);
  auto at = [&](int x, int y) {  // rows bottom to top
    float f = 0;
    memcpy(&f, pfm.data() + header + (static_cast<size_t>(kH - 1 - y) * kW + x) * 4, 4);
    return f;
  };
  EXPECT_NEAR(at(64, 48), 2.0f, 0.3f);   // the square
  EXPECT_NEAR(at(20, 48), -2.0f, 0.3f);  // the wall, beyond the focus plane
  EXPECT_NEAR(at(100, 80), -2.0f, 0.3f);

  // A range the wrong way round is a usage error.
  args[4] = "3,-1";
  EXPECT_EQ(Run(args).exit_code, 2);
}

TEST_F(Cli, TruncatedPpm) {
  auto paths = PpmBurst(3, 64, 48);
  ASSERT_EQ(truncate(paths[1].c_str(), 500), 0);
  ExpectCleanFailure(Run({"run", paths[0], paths[1], paths[2], "--out", Out()}), "f1.ppm",
                     "truncated");
}

TEST_F(Cli, PngWithBrokenCrc) {
  auto paths = PpmBurst(2, 64, 48);
  Bytes png = GreyPng();
  ASSERT_FALSE(png.empty());
  const long idat = test::FindPngChunk(png, "IDAT");
  ASSERT_GT(idat, 0);
  const size_t at = static_cast<size_t>(idat);
  const size_t length = (size_t{png[at]} << 24) | (size_t{png[at + 1]} << 16) |
                        (size_t{png[at + 2]} << 8) | png[at + 3];
  png[at + 8 + length] ^= 0x5A;  // the stored CRC: the data still inflates, the check must fail
  const std::string bad = dir_ + "/bad.png";
  ASSERT_TRUE(test::WriteFile(bad, png));
  ExpectCleanFailure(Run({"run", paths[0], bad, paths[1], "--out", Out()}), "bad.png", "CRC");
}

TEST_F(Cli, TruncatedJpeg) {
  auto paths = PpmBurst(2, 64, 48);
  std::vector<uint8_t> rgb(64 * 48 * 3);
  for (size_t i = 0; i < rgb.size(); ++i)
    rgb[i] = test::Smooth(static_cast<int>(i / 3) % 64, static_cast<int>(i / 192),
                          static_cast<int>(i % 3));
  Bytes jpeg;
  ASSERT_TRUE(test::EncodeJpeg(64, 48, 3, rgb.data(), 90, false, &jpeg));
  jpeg.resize(jpeg.size() / 2);
  const std::string bad = dir_ + "/cut.jpg";
  ASSERT_TRUE(test::WriteFile(bad, jpeg));
  Result r = Run({"run", paths[0], bad, paths[1], "--out", Out()});
  ExpectCleanFailure(r, "cut.jpg", "cut.jpg");
  EXPECT_TRUE(r.err.find("truncated") != std::string::npos ||
              r.err.find("Premature end") != std::string::npos)
      << r.err;
}

TEST_F(Cli, FramesOfDifferentSizes) {
  auto a = PpmBurst(2, 64, 48);
  const std::string big = dir_ + "/big.ppm";
  ASSERT_TRUE(test::WriteFile(
      big, test::EncodePnm("P6", 80, 48, 255, std::vector<uint16_t>(80 * 48 * 3, 7))));
  ExpectCleanFailure(Run({"run", a[0], a[1], big, "--out", Out()}), "big.ppm", "80x48");
}

TEST_F(Cli, EmptyDirectory) {
  const std::string empty = dir_ + "/empty";
  ASSERT_EQ(mkdir(empty.c_str(), 0755), 0);
  ExpectCleanFailure(Run({"run", "--input", empty, "--out", Out()}), empty, "no image files");
}

TEST_F(Cli, OneFrameBurst) {
  auto a = PpmBurst(1, 64, 48);
  ExpectCleanFailure(Run({"run", a[0], "--out", Out()}), "1 frame", "at least 2");
}

TEST_F(Cli, MissingPath) {
  const std::string missing = dir_ + "/no/such/burst";
  ExpectCleanFailure(Run({"run", "--input", missing, "--out", Out()}), missing,
                     "no such file or directory");
}

TEST_F(Cli, UnwritableOutputDirectory) {
  // Running as root ignores permission bits, so the "directory" is a regular file.
  const std::string not_dir = dir_ + "/file";
  ASSERT_TRUE(test::WriteFile(not_dir, Bytes{1, 2, 3}));
  Result r = Run({"run", "--synthetic", "--size", "160x120", "--out", not_dir + "/photo.jpg"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find(not_dir), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(Slurp(not_dir).size(), 3u);
}

// A device, a FIFO, a link or an input frame is never written over.
TEST_F(Cli, OutputOntoSomethingNotARegularFileIsRefusedBeforeWork) {
  const std::vector<std::string> frames = PpmBurst(3, 64, 48);
  ASSERT_EQ(mkfifo((out_dir_ + "/fifo.jpg").c_str(), 0644), 0);
  ASSERT_TRUE(test::WriteFile(dir_ + "/old.jpg", Bytes{9, 9, 9}));
  ASSERT_EQ(symlink((dir_ + "/old.jpg").c_str(), (out_dir_ + "/link.jpg").c_str()), 0);
  const std::string frame0 = Slurp(frames[0]);
  struct Case {
    std::string out, says;
  };
  for (const Case& c :
       {Case{"/dev/null", "not a regular file"}, Case{out_dir_ + "/fifo.jpg", "not a regular file"},
        Case{out_dir_ + "/link.jpg", "symbolic link"},
        Case{frames[0], "is an input of this run"}}) {
    std::vector<std::string> args = {"run", "--geometry", "rectified", "--out", c.out};
    args.insert(args.end(), frames.begin(), frames.end());
    const Result r = Run(args);
    EXPECT_EQ(r.exit_code, 1) << c.out << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
  }
  struct stat st;
  ASSERT_EQ(stat("/dev/null", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode)) << "/dev/null is still the device";
  ASSERT_EQ(lstat((out_dir_ + "/fifo.jpg").c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  ASSERT_EQ(lstat((out_dir_ + "/link.jpg").c_str(), &st), 0);
  EXPECT_TRUE(S_ISLNK(st.st_mode));
  EXPECT_EQ(Slurp(dir_ + "/old.jpg"), std::string(3, 9));
  EXPECT_EQ(Slurp(frames[0]), frame0) << "the input frame is untouched";
}

// `refocus depth` writes the way every output is written.
TEST_F(Cli, DepthOutputsFollowTheFileRule) {
  const std::vector<std::string> frames = PpmBurst(3, 64, 48);
  std::vector<std::string> args = {
      "depth",           "--geometry",        "rectified", "--labels",          "8",
      "--disparity-out", out_dir_ + "/d.pfm", "--preview", out_dir_ + "/d.pfm", "--views"};
  args.insert(args.end(), frames.begin(), frames.end());
  // One file for both outputs: a usage error, nothing written.
  EXPECT_EQ(Run(args).exit_code, 2);
  EXPECT_TRUE(OutDirEmpty());
  // A user's file named like the old fixed temporary survives, and no temporary is left.
  ASSERT_TRUE(test::WriteFile(out_dir_ + "/d.pfm.tmp", Bytes{1, 2}));
  args[8] = out_dir_ + "/p.png";
  Result r = Run(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(Slurp(out_dir_ + "/d.pfm.tmp").size(), 2u);
  EXPECT_EQ(Slurp(out_dir_ + "/d.pfm").rfind("Pf\n64 48\n", 0), 0u);
  EXPECT_EQ(Slurp(out_dir_ + "/p.png").substr(1, 3), "PNG");
  // A preview that cannot be written: exit 1 before any work, and no PFM either.
  ASSERT_EQ(mkfifo((out_dir_ + "/fifo.png").c_str(), 0644), 0);
  args[6] = out_dir_ + "/e.pfm";
  args[8] = out_dir_ + "/fifo.png";
  r = Run(args);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(Slurp(out_dir_ + "/e.pfm"), "");
  // An output folder that does not exist is found before the computation.
  args[6] = dir_ + "/nowhere/d.pfm";
  args[8] = out_dir_ + "/q.png";
  r = Run(args);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find(dir_ + "/nowhere"), std::string::npos) << r.err;
  EXPECT_EQ(Slurp(out_dir_ + "/q.png"), "");
  DIR* d = opendir(out_dir_.c_str());
  while (dirent* e = readdir(d)) {
    const std::string n = e->d_name;
    EXPECT_TRUE(n == "." || n == ".." || n[0] != '.') << "temporary left: " << n;
  }
  closedir(d);
}

// A valid PNG of width x height all-zero RGB pixels, streamed through zlib: 16384 x 16384 is
// about 0.8 MB of file for 0.8 GB of pixels.
Bytes ZeroPng(uint32_t width, uint32_t height) {
  Bytes out = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  auto chunk = [&out](const char* type, const Bytes& data) {
    for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<uint8_t>(data.size() >> s));
    const size_t at = out.size();
    out.insert(out.end(), type, type + 4);
    out.insert(out.end(), data.begin(), data.end());
    const uLong crc = crc32(0, out.data() + at, static_cast<uInt>(out.size() - at));
    for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<uint8_t>(crc >> s));
  };
  Bytes ihdr;
  for (uint32_t v : {width, height})
    for (int s = 24; s >= 0; s -= 8) ihdr.push_back(static_cast<uint8_t>(v >> s));
  ihdr.insert(ihdr.end(), {8, 2, 0, 0, 0});
  chunk("IHDR", ihdr);
  z_stream z = {};
  deflateInit(&z, 9);
  const Bytes row(1 + static_cast<size_t>(width) * 3, 0);
  Bytes idat, buf(1 << 16);
  for (uint32_t y = 0; y < height; ++y) {
    z.next_in = const_cast<Bytef*>(row.data());
    z.avail_in = static_cast<uInt>(row.size());
    const int flush = y + 1 == height ? Z_FINISH : Z_NO_FLUSH;
    do {
      z.next_out = buf.data();
      z.avail_out = static_cast<uInt>(buf.size());
      deflate(&z, flush);
      idat.insert(idat.end(), buf.data(), buf.data() + (buf.size() - z.avail_out));
    } while (z.avail_out == 0);
  }
  deflateEnd(&z);
  chunk("IDAT", idat);
  chunk("IEND", {});
  return out;
}

// A small file that claims a huge image is refused from its header, the
// file named, in little memory.
TEST_F(Cli, HugeViewsAreRefusedFromTheirHeaders) {
  const std::string big = dir_ + "/zero.png";
  ASSERT_TRUE(test::WriteFile(big, ZeroPng(16384, 16384)));
  std::vector<std::string> args = {"depth", "--disparity-out", out_dir_ + "/d.pfm", "--views"};
  for (int v = 0; v < 16; ++v) args.push_back(big);
  long rss_kib = 0;
  const Result r = RunMeasured(args, &rss_kib);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find(big), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("16384x16384"), std::string::npos) << r.err;
  EXPECT_LT(rss_kib, 64 * 1024) << "peak RSS in KiB";
  printf("16 views of a %zu-byte 16384x16384 PNG: refused at %ld KiB peak RSS\n", Slurp(big).size(),
         rss_kib);
  // The same burst for run.
  args = {"run", "--out", Out()};
  for (int v = 0; v < 16; ++v) args.push_back(big);
  const Result run = RunMeasured(args, &rss_kib);
  ExpectCleanFailure(run, big, "16384x16384");
  EXPECT_LT(rss_kib, 64 * 1024) << "peak RSS in KiB";
  EXPECT_TRUE(OutDirEmpty());
}

// No value is changed or ignored without a word, and a usage error
// is one line that says what was wrong.
TEST_F(Cli, NothingIsSilentlyChangedOrIgnored) {
  const std::vector<std::string> frames = PpmBurst(5, 64, 48);
  auto run = [&](std::vector<std::string> args, bool with_frames) {
    if (with_frames) args.insert(args.end(), frames.begin(), frames.end());
    return Run(args);
  };
  struct Case {
    std::vector<std::string> args;
    bool with_frames;
    int exit_code;
    std::string says;
  };
  const std::string out = Out();
  for (const Case& c : std::vector<Case>{
           {{"run", "--ref", "7", "--out", out}, true, 1, "reference frame 7 is past"},
           {{"run", "--size", "4294967616x240", "--out", out}, false, 2, "4294967616x240"},
           {{"run", "--size", "320x240", "--out", out}, true, 2, "--size is for the synthetic"},
           {{"run", "--frames", "3", "--out", out}, true, 2, "--frames is for the synthetic"},
           {{"run", "--out", out, "--out", out + "2"}, false, 2, "--out given twice"},
           {{"run", "--synthetic", "--out"}, false, 2, "--out needs a value"},
           {{"run", "--bogus", "--out", out}, false, 2, "unknown option '--bogus'"},
           {{"run", "--size", "320y240", "--out", out}, false, 2, "--size: '320y240'"},
           {{"rerender", out, "--rotation", "400", "--out", out}, false, 2, "--rotation: '400'"},
           {{"run", "--size", "320x240", "--focus", "5000,5000", "--out", out},
            false,
            1,
            "lies outside the 320x240 photo"},
       }) {
    const Result r = run(c.args, c.with_frames);
    EXPECT_EQ(r.exit_code, c.exit_code) << c.args[1] << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
  }
  EXPECT_TRUE(OutDirEmpty());
  // A working size too small for the motion stage is named as such, not "shoot larger".
  const Result small = Run({"run", "--size", "320x240", "--working-size", "16x16", "--out", out});
  EXPECT_EQ(small.exit_code, 0) << small.err;
  EXPECT_NE(small.err.find("working size bound 16x16"), std::string::npos) << small.err;
  EXPECT_EQ(small.err.find("higher resolution"), std::string::npos) << small.err;
  // Help is asked for: on stdout, exit 0.
  const Result help = Run({"depth", "--help"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("usage: refocus depth"), std::string::npos);
  EXPECT_EQ(help.err, "");
}

// The help and the code agree on the ranges, and libpng's own
// "PNG ..." messages are not prefixed twice.
TEST_F(Cli, HelpAndBehaviourAgree) {
  const Result help = Run({"run", "--help"});
  ASSERT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("1 .. 22"), std::string::npos) << help.out;
  EXPECT_NE(help.out.find("16x16 .. 8192x8192"), std::string::npos) << help.out;
  for (const char* f : {"1", "22"}) {
    const Result r = Run({"run", "--size", "64x48", "--f-number", f, "--out", Out()});
    EXPECT_EQ(r.exit_code, 0) << f << ": " << r.err;
  }
  EXPECT_EQ(Run({"run", "--f-number", "23", "--out", Out()}).exit_code, 2);
  EXPECT_EQ(Run({"run", "--f-number", "0.9", "--out", Out()}).exit_code, 2);
  const Result top = Run({"--help"});
  EXPECT_EQ(top.out.find("rectified views"), std::string::npos) << top.out;

  auto paths = PpmBurst(2, 64, 48);
  Bytes png = GreyPng();
  ASSERT_FALSE(png.empty());
  png[16] = 0x80;  // IHDR width 2^31 + 64: libpng says "PNG unsigned integer out of range"
  const uLong crc = crc32(0, png.data() + 12, 17);  // IHDR's type and data, CRC after them
  for (int k = 0; k < 4; ++k) png[29 + k] = static_cast<uint8_t>(crc >> (24 - 8 * k));
  const std::string bad = dir_ + "/wide.png";
  ASSERT_TRUE(test::WriteFile(bad, png));
  const Result r = Run({"run", paths[0], bad, paths[1], "--out", Out()});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("wide.png"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("PNG PNG"), std::string::npos) << r.err;
}

// The frames' EXIF Orientation goes into the photo, so it shows upright.
TEST_F(Cli, TheFramesOrientationGoesIntoThePhoto) {
  JpegMetadata meta;
  meta.orientation = 6;  // stored turned: the viewer rotates 90 degrees clockwise
  std::vector<uint8_t> exif;
  ASSERT_TRUE(BuildExif(meta, 64, 48, &exif).ok());
  std::vector<std::string> args = {"run", "--geometry", "rectified", "--out", Out()};
  for (int i = 0; i < 3; ++i) {
    std::vector<uint8_t> rgb(64 * 48 * 3);
    for (int y = 0; y < 48; ++y)
      for (int x = 0; x < 64; ++x)
        for (int c = 0; c < 3; ++c) rgb[(y * 64 + x) * 3 + c] = test::Smooth(x + 2 * i, y, c);
    Bytes jpg;
    ASSERT_TRUE(test::EncodeJpeg(64, 48, 3, rgb.data(), 95, false, &jpg));
    // APP1 right after SOI: marker, big-endian length (itself included), the payload.
    const size_t n = exif.size() + 2;
    Bytes app1 = {0xff, 0xe1, static_cast<uint8_t>(n >> 8), static_cast<uint8_t>(n)};
    app1.insert(app1.end(), exif.begin(), exif.end());
    jpg.insert(jpg.begin() + 2, app1.begin(), app1.end());
    args.push_back(dir_ + "/f" + std::to_string(i) + ".jpg");
    ASSERT_TRUE(test::WriteFile(args.back(), jpg));
  }
  ASSERT_EQ(ExifOrientation(args[5].c_str()), 6) << "the test's own frames";
  const Result r = Run(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(ExifOrientation(Out().c_str()), 6);
  // And from the photo into its re-render.
  const std::string again = out_dir_ + "/again.jpg";
  const Result rr = Run({"rerender", Out(), "--out", again});
  ASSERT_EQ(rr.exit_code, 0) << rr.err;
  EXPECT_EQ(ExifOrientation(again.c_str()), 6);
}

// A size the camera cannot take is refused naming the file that has it.
TEST_F(Cli, SizeRefusalsNameTheFile) {
  const std::vector<std::string> tiny = PpmBurst(2, 8, 8);
  Result r = Run({"run", "--out", Out(), tiny[0], tiny[1]});
  ExpectCleanFailure(r, tiny[0], "8x8");
  r = Run({"depth", "--disparity-out", out_dir_ + "/d.pfm", "--views", tiny[0], tiny[1]});
  ExpectCleanFailure(r, tiny[0], "too small to follow the camera's motion");
  const std::vector<std::string> tinier = PpmBurst(2, 4, 4);
  r = Run({"depth", "--geometry", "rectified", "--disparity-out", out_dir_ + "/d.pfm", "--views",
           tinier[0], tinier[1]});
  ExpectCleanFailure(r, tinier[0], "4x4");
}

// refocus depth reads its options as run does: the same settings and messages, and the files
// after --views up to the next option.
TEST_F(Cli, DepthTakesItsOptionsAsRunDoes) {
  const std::vector<std::string> f = PpmBurst(3, 64, 48);
  const std::string pfm = out_dir_ + "/d.pfm";
  struct Case {
    std::vector<std::string> args;
    std::string says;
  };
  for (const Case& c : std::vector<Case>{
           {{"depth", "--labels", "1", "--disparity-out", pfm, "--views", f[0], f[1]},
            "--labels: '1' is not a whole number from 2 to 256"},
           {{"depth", "--working-size", "64x48", "--views", f[0], f[1]},
            "unknown option '--working-size'"},
           {{"depth", "--views", f[0], f[1], "--ref"}, "--ref needs a value"},
           {{"depth", f[0], "--views", f[1], f[2], "--disparity-out", pfm},
            "unknown option '" + f[0] + "'"},
           {{"depth", "--views", f[0], "--subpixel", f[1], "--disparity-out", pfm},
            "unknown option '" + f[1] + "'"},
           {{"depth", "--views", f[0], "--disparity-out", pfm}, "--views needs at least two files"},
       }) {
    const Result r = Run(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.says << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
  }
  EXPECT_TRUE(OutDirEmpty());
  // --views may be given more than once; "--" ends the options.
  const Result r = Run({"depth", "--geometry", "rectified", "--labels", "8", "--views", f[0],
                        "--disparity-out", pfm, "--views", f[1], "--", f[2]});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("3 views (reference 1)"), std::string::npos) << r.out;
  const Result help = Run({"depth", "-h"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_EQ(help.out, Run({"depth", "--help"}).out);
  EXPECT_NE(help.out.find("usage: refocus depth"), std::string::npos);
}

TEST_F(Cli, UsageErrorsExitWithTwo) {
  EXPECT_EQ(Run({"run", "--synthetic"}).exit_code, 2);  // no --out
  EXPECT_EQ(Run({"run", "--f-number", "fast", "--out", Out()}).exit_code, 2);
  EXPECT_EQ(Run({"frobnicate"}).exit_code, 2);
  EXPECT_TRUE(OutDirEmpty());
}

}  // namespace
}  // namespace lb
