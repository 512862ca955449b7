// Dynamic Depth written beside GDepth and read back: by the product's reader, by exiftool and by
// an independent Python parser (dd_slice.py); a file without its GDepth part; and the malformed
// directories, each refused in one line naming the file, without allocating.
#include "firmware/refocusable/dynamic_depth.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "firmware/codecs/png_writer.h"
#include "firmware/storage/atomic_file.h"
#include "tests/firmware/refocusable/refocusable_test_util.h"
#include "tests/support/alloc_counter.h"

namespace lb {
namespace {

struct DdFile {
  test::RefocusSample sample;
  DynamicDepthExtras extras;
  std::vector<uint8_t> bytes;
};

// The product's file: GDepth (and GImage when `large`) and Dynamic Depth, with a confidence map.
DdFile MakeDdFile(bool large) {
  DdFile f;
  f.sample = test::MakeRefocusSample(large);
  test::RefocusSample& s = f.sample;
  std::vector<uint16_t> confidence(s.disp_q8.size(), 200);
  EXPECT_TRUE(
      EncodeGrayPng(MakeView<const uint16_t>(confidence.data(), s.disp_width, s.disp_height), 8,
                    &s.xmp.depth.confidence)
          .ok());
  f.extras.imaging_model = {
      400.0,           400.0,           s.picture.width / 2.0, s.picture.height / 2.0,
      s.picture.width, s.picture.height};
  EXPECT_TRUE(SetDynamicDepth(f.extras, &s.xmp).ok());
  EXPECT_TRUE(BuildXmpSegments(s.xmp, &s.segments).ok());
  f.bytes = test::WriteRefocusJpeg(s, s.segments);
  EXPECT_TRUE(AppendDynamicDepthItems(s.xmp, f.extras, &f.bytes).ok());
  return f;
}

// The same photo and items with only Dynamic Depth in its XMP (no GDepth, GImage, GFocus), the
// Device element as `description` gives it.
std::vector<uint8_t> DdOnly(const DdFile& f, std::string description) {
  JpegSegment main;
  const std::string packet = std::string(kXmpSignature, sizeof(kXmpSignature)) +
                             "<x:xmpmeta xmlns:x=\"adobe:ns:meta/\">\n <rdf:RDF xmlns:rdf=\""
                             "http://www.w3.org/1999/02/22-rdf-syntax-ns#\">\n" +
                             description + " </rdf:RDF>\n</x:xmpmeta>";
  test::SetPayloadText(&main, packet);
  std::vector<uint8_t> bytes = test::WriteRefocusJpeg(f.sample, {main});
  EXPECT_TRUE(AppendDynamicDepthItems(f.sample.xmp, f.extras, &bytes).ok());
  return bytes;
}

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

std::string WriteFile(const test::ScratchDir& dir, const std::vector<uint8_t>& bytes) {
  const std::string path = dir.Path("dd.jpg");
  AtomicFile file;
  EXPECT_TRUE(file.Open(path.c_str()).ok());
  EXPECT_TRUE(file.Write(bytes.data(), bytes.size()).ok());
  EXPECT_TRUE(file.Commit().ok());
  return path;
}

Status ReadDd(const std::vector<uint8_t>& bytes, DynamicDepthFields* dd) {
  RefocusableBuffers memory;  // no extended XMP in these files: no memory needed
  RefocusableFields f;
  std::string_view main, extended;
  LB_RETURN_IF_ERROR(
      ReadXmpPackets(bytes.data(), bytes.size(), "dd.jpg", memory, &f, &main, &extended));
  return ReadDynamicDepthFields(bytes.data(), bytes.size(), "dd.jpg", main, extended, f.width,
                                f.height, dd);
}

std::vector<uint8_t> Bytes(const DynamicDepthItem& item) {
  return std::vector<uint8_t>(item.data, item.data + item.length);
}

class DynamicDepthTest : public ::testing::TestWithParam<bool> {};

TEST_P(DynamicDepthTest, RoundTripsBesideGDepth) {
  const DdFile f = MakeDdFile(GetParam());
  const test::RefocusSample& s = f.sample;
  ASSERT_EQ(s.segments.size() > 1, GetParam());  // the large one's data in extended XMP
  RefocusableImage image;
  Status status = ReadRefocusable(f.bytes.data(), f.bytes.size(), "dd.jpg", &image);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(image.xmp.depth.data, s.xmp.depth.data);  // GDepth first, when both are there

  std::vector<uint8_t> extended_text(1 << 20);
  std::vector<ExtendedXmpChunk> chunks(s.segments.size());
  RefocusableBuffers memory;
  memory.chunks = chunks.data();
  memory.chunk_capacity = chunks.size();
  memory.extended = extended_text.data();
  memory.extended_capacity = extended_text.size();
  RefocusableFields fields;
  std::string_view main, extended;
  ASSERT_TRUE(
      ReadXmpPackets(f.bytes.data(), f.bytes.size(), "dd.jpg", memory, &fields, &main, &extended)
          .ok());
  DynamicDepthFields dd;
  status = ReadDynamicDepthFields(f.bytes.data(), f.bytes.size(), "dd.jpg", main, extended,
                                  fields.width, fields.height, &dd);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(dd.item_count, GetParam() ? 4u : 3u);
  EXPECT_EQ(dd.format, "RangeInverse");
  EXPECT_EQ(dd.units, "Diopters");
  EXPECT_EQ(dd.near_depth, s.xmp.depth.near_depth);
  EXPECT_EQ(dd.far_depth, s.xmp.depth.far_depth);
  ASSERT_GE(dd.depth, 0);
  EXPECT_EQ(Bytes(dd.items[dd.depth]), s.xmp.depth.data);
  EXPECT_EQ(dd.items[dd.depth].mime, "image/png");
  EXPECT_EQ(dd.depth_header.width, s.disp_width);
  EXPECT_EQ(dd.depth_header.height, s.disp_height);
  ASSERT_GE(dd.confidence, 0);
  EXPECT_EQ(Bytes(dd.items[dd.confidence]), f.sample.xmp.depth.confidence);
  if (GetParam()) {
    ASSERT_GE(dd.original, 0);
    EXPECT_EQ(Bytes(dd.items[dd.original]), s.xmp.image);
  } else {
    EXPECT_EQ(dd.original, -1);
  }
  // The primary is the file up to its EOI, a whole JPEG.
  const DynamicDepthItem& primary = dd.items[0];
  EXPECT_EQ(primary.data, f.bytes.data());
  EXPECT_EQ(primary.data[primary.length - 1], 0xD9);
}

// With its GDepth part removed, the file still reads, through Dynamic Depth alone: the same
// depth values and original, and through fixed buffers without allocating.
TEST_P(DynamicDepthTest, ReadsWithoutGDepth) {
  const DdFile f = MakeDdFile(GetParam());
  const std::vector<uint8_t> bytes = DdOnly(f, f.sample.xmp.extra_description);
  RefocusableImage gdepth, dd;
  ASSERT_TRUE(ReadRefocusable(f.bytes.data(), f.bytes.size(), "both.jpg", &gdepth).ok());
  const Status status = ReadRefocusable(bytes.data(), bytes.size(), "dd.jpg", &dd);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(dd.depth.values, gdepth.depth.values);
  EXPECT_EQ(dd.depth.bits, gdepth.depth.bits);
  EXPECT_EQ(dd.xmp.depth.near_depth, gdepth.xmp.depth.near_depth);
  EXPECT_EQ(dd.xmp.depth.units, "Diopters");
  EXPECT_EQ(dd.xmp.image, f.sample.xmp.image);

  RefocusableBuffers memory;
  RefocusableFields fields;
  const size_t before = testing::AllocationCount();
  ASSERT_TRUE(ReadRefocusableFields(bytes.data(), bytes.size(), "dd.jpg", memory, &fields).ok());
  EXPECT_EQ(testing::AllocationCount(), before);
  EXPECT_TRUE(fields.dynamic_depth);
  EXPECT_EQ(std::vector<uint8_t>(fields.depth_png, fields.depth_png + fields.depth_png_size),
            f.sample.xmp.depth.data);
}

// Without the original as an item (its bytes once, in GImage only): the directory lists the
// primary, the depth and the confidence, and the Camera's Image names the primary.
TEST(DynamicDepthWriterTest, OriginalMayStayInGImageOnly) {
  DdFile f = MakeDdFile(true);
  f.extras.original = false;
  ASSERT_TRUE(SetDynamicDepth(f.extras, &f.sample.xmp).ok());
  const std::vector<uint8_t> bytes = DdOnly(f, f.sample.xmp.extra_description);
  DynamicDepthFields dd;
  const Status status = ReadDd(bytes, &dd);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(dd.item_count, 3u);
  EXPECT_EQ(dd.original, -1);
  EXPECT_EQ(Bytes(dd.items[dd.depth]), f.sample.xmp.depth.data);
  EXPECT_NE(f.sample.xmp.extra_description.find("Image:ItemURI=\"primary_image\""),
            std::string::npos);
}

// A directory as some phones write it: GContainer's namespaces, items named by Item:Semantic
// (no DataURI), fields as elements, a gain map between the primary and the depth: the depth, the
// confidence and the original are found by what names them, not by their position.
TEST(DynamicDepthReaderTest, GContainerDirectoryBySemantic) {
  const DdFile f = MakeDdFile(true);
  const RefocusableXmp& x = f.sample.xmp;
  const auto item = [](const char* mime, const char* semantic, size_t length) {
    return std::string("     <rdf:li rdf:parseType=\"Resource\">\n      <Container:Item>\n") +
           "       <Item:Mime>" + mime + "</Item:Mime>\n       <Item:Semantic>" + semantic +
           "</Item:Semantic>\n       <Item:Length>" + std::to_string(length) +
           "</Item:Length>\n      </Container:Item>\n     </rdf:li>\n";
  };
  const std::string description =
      std::string("  <rdf:Description rdf:about=\"\"\n") + "    xmlns:Container=\"" +
      kGContainerNs + "\" xmlns:Item=\"" + kGContainerItemNs + "\"\n    xmlns:Device=\"" +
      kDdDeviceNs + "\" xmlns:Camera=\"" + kDdCameraNs + "\"\n    xmlns:DepthMap=\"" +
      kDdDepthMapNs + "\" xmlns:Image=\"" + kDdImageNs + "\">\n" +
      "   <Container:Directory>\n    <rdf:Seq>\n" + item("image/jpeg", "Primary", 0) +
      item("image/jpeg", "GainMap", x.image.size()) +
      item("image/png", "Depth", x.depth.data.size()) +
      item("image/png", "Confidence", f.sample.xmp.depth.confidence.size()) +
      item("image/jpeg", "Original", x.image.size()) +
      "    </rdf:Seq>\n   </Container:Directory>\n   <Device:Cameras><rdf:Seq><rdf:li "
      "rdf:parseType=\"Resource\"><Device:Camera rdf:parseType=\"Resource\">\n"
      "    <Camera:DepthMap rdf:parseType=\"Resource\">\n"
      "     <DepthMap:Format>RangeLinear</DepthMap:Format><DepthMap:Near>0.5</DepthMap:Near>\n"
      "     <DepthMap:Far>4</DepthMap:Far><DepthMap:Units>Meters</DepthMap:Units>\n"
      "     <DepthMap:DepthURI>android/depthmap</DepthMap:DepthURI>\n"
      "     <DepthMap:ConfidenceURI>android/confidencemap</DepthMap:ConfidenceURI>\n"
      "    </Camera:DepthMap>\n"
      "    <Camera:Image Image:ItemSemantic=\"Original\" Image:ItemURI=\"android/original\"/>\n"
      "   </Device:Camera></rdf:li></rdf:Seq></Device:Cameras>\n  </rdf:Description>\n";
  JpegSegment main;
  test::SetPayloadText(&main, std::string(kXmpSignature, sizeof(kXmpSignature)) +
                                  "<x:xmpmeta xmlns:x=\"adobe:ns:meta/\"><rdf:RDF xmlns:rdf=\""
                                  "http://www.w3.org/1999/02/22-rdf-syntax-ns#\">\n" +
                                  description + "</rdf:RDF></x:xmpmeta>");
  std::vector<uint8_t> bytes = test::WriteRefocusJpeg(f.sample, {main});
  for (const std::vector<uint8_t>* part :
       {&x.image, &x.depth.data, &f.sample.xmp.depth.confidence, &x.image})
    bytes.insert(bytes.end(), part->begin(), part->end());
  DynamicDepthFields dd;
  const Status status = ReadDd(bytes, &dd);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(dd.item_count, 5u);
  EXPECT_EQ(dd.depth, 2);
  EXPECT_EQ(dd.confidence, 3);
  EXPECT_EQ(dd.original, 4);
  EXPECT_EQ(dd.format, "RangeLinear");
  EXPECT_EQ(dd.units, "Meters");
  EXPECT_EQ(dd.near_depth, 0.5);
  EXPECT_EQ(dd.far_depth, 4.0);
  EXPECT_EQ(Bytes(dd.items[dd.depth]), x.depth.data);
  EXPECT_EQ(Bytes(dd.items[dd.original]), x.image);
  if (test::HaveTool("python3")) {
    test::ScratchDir dir;
    const std::string path = WriteFile(dir, bytes);
    const char* source = getenv("LB_SOURCE_DIR");
    int code = 0;
    const std::string out =
        test::RunTool(std::string("python3 '") + (source != nullptr ? source : ".") +
                          "/tests/firmware/refocusable/dd_slice.py' '" + path + "' 2>&1",
                      &code);
    // The independent parser slices the same items (it resolves URIs only, so stops there).
    EXPECT_NE(out.find("2 image/png " + std::to_string(x.depth.data.size()) + " Depth "),
              std::string::npos)
        << out;
  }
}

INSTANTIATE_TEST_SUITE_P(Sizes, DynamicDepthTest, ::testing::Values(false, true),
                         [](const auto& info) { return info.param ? "Extended" : "OnePacket"; });

// Every way the directory can disagree with the file: refused in one line naming the file, by
// the fields reader alone, before anything is decoded and without allocating.
TEST(DynamicDepthMalformedTest, RefusedInOneLineNamingTheFile) {
  const DdFile f = MakeDdFile(true);
  const std::string& good = f.sample.xmp.extra_description;
  const size_t depth_size = f.sample.xmp.depth.data.size();
  const std::string depth_length = "Item:Length=\"" + std::to_string(depth_size) + "\"";
  // A grey JPEG whose frame header says 16384x16384, in a file of a few kilobytes.
  std::vector<uint8_t> huge;
  ASSERT_TRUE(EncodeYCbCr420(test::MakeTexture(16, 16).View(), 90, &huge).ok());
  for (size_t i = 2; i + 8 < huge.size(); ++i) {
    if (huge[i] == 0xFF && huge[i + 1] == 0xC0) {
      huge[i + 5] = huge[i + 7] = 0x40;
      huge[i + 6] = huge[i + 8] = 0x00;
      break;
    }
  }
  struct Case {
    const char* what;
    std::string description;
    const char* message;
  } cases[] = {
      {"length past the end", Replace(good, depth_length, "Item:Length=\"99999999\""),
       "past the end"},
      {"lengths that do not add up",
       Replace(good, depth_length, "Item:Length=\"" + std::to_string(depth_size + 1) + "\""),
       "do not add up"},
      {"missing depth item",
       Replace(good, "DepthMap:DepthURI=\"android/depthmap", "DepthMap:DepthURI=\"android/nodepth"),
       "names no Container item"},
      {"unknown mime", Replace(good, "Item:Mime=\"image/png", "Item:Mime=\"image/x-depth"),
       "unknown Item:Mime"},
      {"no DepthMap", Replace(good, "<Camera:DepthMap", "<Camera:Other"), "without a DepthMap"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    const std::vector<uint8_t> bytes = DdOnly(f, c.description);
    RefocusableBuffers memory;
    RefocusableFields fields;
    const size_t before = testing::AllocationCount();
    const Status status =
        ReadRefocusableFields(bytes.data(), bytes.size(), "dd.jpg", memory, &fields);
    EXPECT_EQ(testing::AllocationCount(), before);
    ASSERT_FALSE(status.ok());
    const std::string message = status.message();
    EXPECT_EQ(message.rfind("dd.jpg: ", 0), 0u) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_NE(message.find(c.message), std::string::npos) << message;
  }

  // The huge depth item, by its header: refused before a pixel is decoded.
  DdFile big = MakeDdFile(false);
  big.sample.xmp.depth.data = huge;
  big.sample.xmp.depth.mime = "image/jpeg";
  ASSERT_TRUE(SetDynamicDepth(big.extras, &big.sample.xmp).ok());
  const std::vector<uint8_t> bytes = DdOnly(big, big.sample.xmp.extra_description);
  ASSERT_LT(bytes.size(), 64u << 10);
  RefocusableImage image;
  const Status status = ReadRefocusable(bytes.data(), bytes.size(), "dd.jpg", &image);
  ASSERT_FALSE(status.ok());
  const std::string message = status.message();
  EXPECT_EQ(message.rfind("dd.jpg: ", 0), 0u) << message;
  EXPECT_NE(message.find("16384x16384"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_TRUE(image.depth.values.empty());
  RefocusableBuffers memory;
  RefocusableFields fields;
  const size_t before = testing::AllocationCount();
  const Status fixed = ReadRefocusableFields(bytes.data(), bytes.size(), "dd.jpg", memory, &fields);
  EXPECT_EQ(testing::AllocationCount(), before);
  EXPECT_NE(std::string(fixed.message()).find("16384x16384"), std::string::npos) << fixed.message();
}

// exiftool, an independent reader, lists the directory and the DepthMap fields; dd_slice.py,
// another, slices the items from the end of the file and finds each a valid image of its Mime.
TEST(DynamicDepthToolsTest, ExiftoolAndAPythonParserReadTheItems) {
  const DdFile f = MakeDdFile(true);
  test::ScratchDir dir;
  const std::string path = WriteFile(dir, f.bytes);
  int code = 0;
  if (test::HaveTool("exiftool")) {
    const std::string out = test::RunTool("exiftool -a -G1 -s '" + path + "' 2>&1", &code);
    EXPECT_EQ(code, 0) << out;
    for (const char* want :
         {"[XMP-Device]", "ContainerDirectoryItemMime",
          "image/jpeg, image/png, image/png, image/jpeg", "ContainerDirectoryItemLength",
          "ContainerDirectoryItemDataURI", "DepthMapFormat", "RangeInverse", "DepthMapUnits",
          "Diopters", "DepthMapNear", "DepthMapFar", "DepthMapDepthURI", "android/depthmap",
          "ImageItemURI", "android/originalimage"}) {
      EXPECT_NE(out.find(want), std::string::npos) << want << "\n" << out;
    }
    EXPECT_EQ(out.find("Warning"), std::string::npos) << out;
  }
  if (!test::HaveTool("python3")) GTEST_SKIP() << "python3 not installed";
  const char* source = getenv("LB_SOURCE_DIR");
  const std::string script =
      std::string(source != nullptr ? source : ".") + "/tests/firmware/refocusable/dd_slice.py";
  const std::string out = test::RunTool("python3 '" + script + "' '" + path + "' 2>&1", &code);
  ASSERT_EQ(code, 0) << out;
  const test::RefocusSample& s = f.sample;
  const std::string dims = std::to_string(s.disp_width) + "x" + std::to_string(s.disp_height);
  for (const std::string& want :
       {std::string("0 image/jpeg "),
        "1 image/png " + std::to_string(s.xmp.depth.data.size()) + " android/depthmap " + dims,
        "2 image/png " + std::to_string(f.sample.xmp.depth.confidence.size()) +
            " android/confidencemap " + dims,
        "3 image/jpeg " + std::to_string(s.xmp.image.size()) + " android/originalimage " +
            std::to_string(s.picture.width) + "x" + std::to_string(s.picture.height),
        std::string("depth 1\n"), std::string("original 3\n")}) {
    EXPECT_NE(out.find(want), std::string::npos) << want << "\n" << out;
  }
}

}  // namespace
}  // namespace lb
