// A captured frame as a domain (bench/capture/, bench/pipeline/captured.h):
// the OpenEXR file read and written, its values decoded to eye depth, its
// pixels as the population, bits lost per pixel and their picture, and the
// scene files that name a capture.
#include <cmath>
#include <fstream>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <gtest/gtest.h>

#include "bench/backends/cpu/cpu_backend.h"
#include "bench/capture/depth_capture.h"
#include "bench/capture/example_frame.h"
#include "bench/choose/choose.h"
#include "bench/choose/scene.h"
#include "bench/numerics/formulas.h"
#include "tests/command_runner.h"

namespace depthbench {
namespace {

const std::string kScenes = std::string(DEPTHBENCH_SOURCE_DIR) + "/bench/scenes/";

std::string Read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// The committed example is what the tool renders now: a change to the raster
// model or the scene that moves one value fails here until the file is
// rendered again (depthbench_example_capture).
TEST(CaptureTest, TheCommittedExampleIsWhatTheToolRenders) {
  const Expected<CaptureImage> committed = ReadDepthExr(kScenes + "captured_frame.exr");
  ASSERT_TRUE(committed.ok()) << committed.status().message();
  const CaptureImage rendered = RenderExampleCapture();
  EXPECT_EQ(committed->channel, "Z");
  EXPECT_EQ(committed->channel_type, "float");
  ASSERT_EQ(committed->width, rendered.width);
  ASSERT_EQ(committed->height, rendered.height);
  std::size_t drawn = 0;
  for (std::size_t p = 0; p < rendered.values.size(); ++p) {
    ASSERT_EQ(std::bit_cast<std::uint32_t>(committed->values[p]), std::bit_cast<std::uint32_t>(rendered.values[p]))
        << "pixel " << p;
    drawn += rendered.values[p] != 0.0f;
  }
  // The ground, the wall and the boxes cover a little more than half the
  // frame; the sky above the wall keeps the clear value.
  EXPECT_GT(drawn, rendered.values.size() / 2);
  EXPECT_LT(drawn, rendered.values.size() * 3 / 4);
}

TEST(CaptureTest, WritesAndReadsBackEveryBit) {
  const std::string dir = testing::MakeTempDir("capture_roundtrip");
  CaptureImage image{3, 2, "depth", "float", {0.0f, 1.0f, 0.5f, 1e-30f, std::nextafter(1.0f, 0.0f), 0.25f}};
  ASSERT_TRUE(WriteDepthExr(dir + "/a.exr", image).ok());
  const Expected<CaptureImage> back = ReadDepthExr(dir + "/a.exr");
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->values, image.values);
  EXPECT_EQ(back->channel, "depth");
  // Asked for by name, and a name it does not have.
  EXPECT_TRUE(ReadDepthExr(dir + "/a.exr", "depth").ok());
  const Expected<CaptureImage> wrong = ReadDepthExr(dir + "/a.exr", "dept");
  ASSERT_FALSE(wrong.ok());
  EXPECT_NE(wrong.status().message().find("no channel 'dept'; it has depth; did you mean 'depth'?"), std::string::npos)
      << wrong.status().message();
  std::filesystem::remove_all(dir);
}

TEST(CaptureTest, FilesItCannotUseAreRefusedByName) {
  const std::string dir = testing::MakeTempDir("capture_bad");
  EXPECT_NE(ReadDepthExr(dir + "/none.exr").status().message().find("none.exr: no such file"), std::string::npos);
  std::ofstream(dir + "/text.exr") << "not an image\n";
  const std::string text = ReadDepthExr(dir + "/text.exr").status().message();
  EXPECT_NE(text.find("text.exr: not an OpenEXR image depthbench can read"), std::string::npos) << text;

  // Several channels (an RGBA dump): which one is depth must be said.
  {
    Imf::Header header(2, 2);
    for (const char* c : {"R", "G"}) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    std::vector<float> r(4, 0.5f), g(4, 0.25f);
    Imf::OutputFile file((dir + "/rg.exr").c_str(), header);
    Imf::FrameBuffer buffer;
    buffer.insert("R", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(r.data()), 4, 8));
    buffer.insert("G", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(g.data()), 4, 8));
    file.setFrameBuffer(buffer);
    file.writePixels(2);
  }
  const std::string two = ReadDepthExr(dir + "/rg.exr").status().message();
  EXPECT_NE(two.find("2 channels (G, R); name the depth channel"), std::string::npos) << two;
  const Expected<CaptureImage> green = ReadDepthExr(dir + "/rg.exr", "G");
  ASSERT_TRUE(green.ok());
  EXPECT_EQ(green->values, std::vector<float>(4, 0.25f));
  std::filesystem::remove_all(dir);
}

// Window depth goes back to the eye depth that stored it, through the
// projection's convention; the clear value is background; values no depth
// buffer holds are errors naming the pixel.
TEST(CaptureTest, DecodesWindowDepthThroughTheProjection) {
  const double near = 0.1, far = 1000.0;
  const std::vector<double> depths = {0.1, 0.37, 5.0, 123.0, 999.0};
  for (Convention c : {Convention::kStandard, Convention::kReversed, Convention::kReversedInf}) {
    const std::uint32_t bits = Info(c).bits;
    const double f = (bits & f32::DB_CONVENTION_INFINITE) != 0u ? INFINITY : far;
    CaptureImage image{static_cast<std::uint32_t>(depths.size()) + 1, 1, "Z", "float", {}};
    for (double z : depths) {
      const DoubleDouble dd_far = std::isfinite(f) ? DoubleDouble(f) : DoubleDouble(0.0);
      image.values.push_back(
          RoundToFloat(hp::window_depth_from_eye_depth(DoubleDouble(near), dd_far, bits, DoubleDouble(z))));
    }
    image.values.push_back((bits & f32::DB_CONVENTION_REVERSED) != 0u ? 0.0f : 1.0f);  // the clear value
    const Expected<CapturedPixels> pixels = DecodeCapture(image, "t.exr", CaptureStores::kWindowDepth, c, near, f);
    ASSERT_TRUE(pixels.ok()) << pixels.status().message();
    EXPECT_EQ(pixels->background, 1u) << Info(c).name;
    EXPECT_TRUE(std::isnan(pixels->eye_depth.back()));
    for (std::size_t k = 0; k < depths.size(); ++k) {
      // The float32 window depth moves the eye depth by its own rounding
      // times the mapping's condition: up to 2^-24 * far / near relative
      // near the far plane of standard Z, so 1e-3 holds every convention.
      EXPECT_NEAR(pixels->eye_depth[k] / depths[k], 1.0, 1e-3) << Info(c).name << " z " << depths[k];
    }
  }
  CaptureImage bad{2, 2, "Z", "float", {0.5f, 0.5f, 0.5f, 1.5f}};
  const std::string message =
      DecodeCapture(bad, "b.exr", CaptureStores::kWindowDepth, Convention::kStandard, near, far).status().message();
  EXPECT_NE(message.find("b.exr: pixel (1, 1) holds 1.5; a depth buffer holds window depth in [0, 1]"),
            std::string::npos)
      << message;
  // Linear depth: eye depth itself; 0 and infinity are nothing drawn.
  CaptureImage linear{4, 1, "Z", "float", {2.5f, 0.0f, INFINITY, 700.0f}};
  const Expected<CapturedPixels> eye =
      DecodeCapture(linear, "l.exr", CaptureStores::kEyeDepth, Convention::kStandard, near, far);
  ASSERT_TRUE(eye.ok());
  EXPECT_EQ(eye->eye_depth[0], 2.5);
  EXPECT_EQ(eye->eye_depth[3], 700.0);
  EXPECT_EQ(eye->background, 2u);
  linear.values[1] = -1.0f;
  EXPECT_FALSE(DecodeCapture(linear, "l.exr", CaptureStores::kEyeDepth, Convention::kStandard, near, far).ok());
}

Expected<Scene> ExampleScene() { return LoadScene(kScenes + "captured_frame.toml"); }

// The scene's pixels are its population: each drawn pixel once, at its own
// place, and only those within the eye-depth range asked about.
TEST(CaptureTest, ThePixelsAreThePopulation) {
  const Expected<Scene> scene = ExampleScene();
  ASSERT_TRUE(scene.ok()) << scene.status().message();
  const Domain& d = scene->domain;
  ASSERT_TRUE(d.capture);
  const CapturedPixels& pixels = *d.capture;
  EXPECT_EQ(d.resolutions, (std::vector<Resolution>{{320, 180}}));
  const CapturedSource all(d);
  EXPECT_EQ(all.sample_count(), pixels.eye_depth.size() - pixels.background);
  const Frame frame = all.FrameAt(7);
  EXPECT_EQ(frame.index, 7u);
  EXPECT_EQ(frame.width, 320u);
  EXPECT_NEAR(frame.near, 0.1, 1e-6);
  for (std::uint64_t i : {std::uint64_t{0}, all.sample_count() / 2, all.sample_count() - 1}) {
    const PixelSample s = all.SampleAt(i, frame);
    const std::uint32_t pixel = all.PixelOf(i);
    EXPECT_EQ(s.x + s.y * 320u, pixel);
    EXPECT_EQ(s.eye_depth, pixels.eye_depth[pixel]);
  }
  Domain far_part = d;
  far_part.eye_depth = Range{100.0, 1000.0};
  const CapturedSource far(far_part);
  EXPECT_GT(far.sample_count(), 0u);
  EXPECT_LT(far.sample_count(), all.sample_count() / 4);
  for (std::uint64_t i = 0; i < far.sample_count(); ++i) EXPECT_GE(far.SampleAt(i, frame).eye_depth, 100.0);
}

// Bits lost per pixel follow the theory for reversed Z in 24-bit unorm at
// f/n 1e4: the stored code's half step 2^-25 over d ~ n/z, through z = n/d,
// is a relative error of 2^-25 (f - n) z / (n f) ~ 2^-25 * 1e4 * z/far,
// about 12 bits lost (log2(2.5e-4) + 24) at the wall 850 m out and under 6
// within 10 m; background pixels have none.
TEST(CaptureTest, BitsLostPerPixelFollowTheTheory) {
  const Expected<Scene> scene = ExampleScene();
  ASSERT_TRUE(scene.ok()) << scene.status().message();
  const auto cpu = MakeCpuBackend();
  const Cell cell{Variant::kInverseVp, Convention::kReversed, Format::kX8D24Unorm};
  const Expected<std::vector<float>> bits = BitsLostPerPixel(scene->domain, cell, *cpu);
  ASSERT_TRUE(bits.ok()) << bits.status().message();
  const CapturedPixels& pixels = *scene->domain.capture;
  float worst_far = 0.0f, worst_near = 0.0f;
  std::uint64_t background = 0;
  for (std::size_t p = 0; p < bits->size(); ++p) {
    const double z = pixels.eye_depth[p];
    if (std::isnan(z)) {
      EXPECT_TRUE(std::isnan((*bits)[p]));
      ++background;
      continue;
    }
    ASSERT_FALSE(std::isnan((*bits)[p])) << "pixel " << p;
    if (z > 700.0) worst_far = std::max(worst_far, (*bits)[p]);
    if (z < 10.0) worst_near = std::max(worst_near, (*bits)[p]);
  }
  EXPECT_EQ(background, pixels.background);
  // The worst of a thousand pixels reaches the half step within a quarter
  // bit (the judge's bins), plus a quarter for the ray's own rounding.
  EXPECT_NEAR(worst_far, 12.0, 0.5);
  EXPECT_LT(worst_near, 6.0);
}

TEST(CaptureTest, ThePictureHasTheFrameAndItsScale) {
  EXPECT_EQ(BitsColour(0.0f), (std::array<std::uint8_t, 3>{20, 20, 110}));
  EXPECT_EQ(BitsColour(24.0f), (std::array<std::uint8_t, 3>{215, 25, 30}));
  EXPECT_EQ(BitsColour(30.0f), BitsColour(24.0f));  // clamped
  EXPECT_NE(BitsColour(10.0f), BitsColour(11.0f));
  const std::string dir = testing::MakeTempDir("capture_png");
  std::vector<float> bits = {0.0f, 12.0f, NAN, 24.0f, 3.0f, 7.0f};
  ASSERT_TRUE(WriteBitsLostPng(dir + "/b.png", 3, 2, bits).ok());
  const std::string png = Read(dir + "/b.png");
  ASSERT_GT(png.size(), 33u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  // IHDR: width 3, height 2 + the gap and the bar (16 rows).
  const auto be32 = [&](std::size_t at) {
    return (std::uint32_t(std::uint8_t(png[at])) << 24) | (std::uint32_t(std::uint8_t(png[at + 1])) << 16) |
           (std::uint32_t(std::uint8_t(png[at + 2])) << 8) | std::uint32_t(std::uint8_t(png[at + 3]));
  };
  EXPECT_EQ(be32(16), 3u);
  EXPECT_EQ(be32(20), 18u);
  EXPECT_FALSE(WriteBitsLostPng(dir + "/no/such/folder/b.png", 3, 2, bits).ok());
  std::filesystem::remove_all(dir);
}

TEST(CaptureTest, SceneFilesNameTheirCapture) {
  const std::string matrix = R"([projection]
matrix = [0.974278629, 0, 0, 0, 0, 1.7320509, 0, 0, 0, 0, 0.000100010002, -1, 0, 0, 0.10001, 0]
api = "vulkan"
layout = "column-major"
[requirement]
relative_error = 1e-5
)";
  const auto parse = [&](const std::string& extra) { return ParseScene(matrix + extra, kScenes + "inline.toml"); };
  const Expected<Scene> ok = parse("[capture]\nfile = \"captured_frame.exr\"\ncamera_position = [100, 0, 0]\n");
  ASSERT_TRUE(ok.ok()) << ok.status().message();
  EXPECT_EQ(ok->domain.camera_distance, (Range{100.0, 100.0}));
  EXPECT_EQ(ok->resolution, (Resolution{320, 180}));

  const auto error = [&](const std::string& extra) { return parse(extra).status().message(); };
  EXPECT_NE(error("[capture]\nfile = \"nothing.exr\"\n").find("capture.file"), std::string::npos);
  EXPECT_NE(error("[capture]\nfile = \"nothing.exr\"\n").find("nothing.exr: no such file"), std::string::npos);
  EXPECT_NE(error("[capture]\nstores = \"window-depth\"\n").find("capture.file"), std::string::npos);
  EXPECT_NE(error("[capture]\nfile = \"captured_frame.exr\"\nstores = \"depth\"\n").find("window-depth"),
            std::string::npos);
  EXPECT_NE(error("[capture]\nfile = \"captured_frame.exr\"\ncamera_position = [1, 2]\n").find("[x, y, z]"),
            std::string::npos);
  EXPECT_NE(error("[capture]\nfile = \"captured_frame.exr\"\nchannel = \"R\"\n").find("no channel 'R'"),
            std::string::npos);
  // Window depth needs the projection's convention to decode.
  const Expected<Scene> no_matrix = ParseScene(R"([projection]
near = 0.1
far = 1000
fov_degrees = 60
aspect = 1.7778
[capture]
file = "captured_frame.exr"
[requirement]
relative_error = 1e-5
)",
                                               kScenes + "inline.toml");
  ASSERT_FALSE(no_matrix.ok());
  EXPECT_NE(no_matrix.status().message().find("give projection.matrix"), std::string::npos)
      << no_matrix.status().message();
}

// choose over the capture: its population is named, and the deepest
// pixels (the wall, 550 to 950 m out), not the far plane, are its far end.
TEST(CaptureTest, ChooseJudgesTheFramesPixels) {
  const auto r = testing::RunDepthbench({"choose", "--scene", kScenes + "captured_frame.toml", "--backend", "cpu"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("population: the 32136 drawn pixels of"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("choice: "), std::string::npos) << r.out;
}

}  // namespace
}  // namespace depthbench
