#include "reconstruct/eval/report.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <regex>

namespace casual3d::eval {
namespace {

PhotoModelEvaluation MakeEvaluation(const std::string& label, double error) {
  PhotoModelEvaluation e;
  e.label = label;
  e.source = label + "/master.exr";
  e.poses_from = "capture/sparse";
  e.pano_width = 256;
  e.pano_height = 128;
  e.stage_seconds = {{"sparse", 12.5}, {"dense", 40.25}};
  e.error_histogram.assign(256, 0);
  for (int i = 0; i < 2; ++i) {
    PhotoEvaluation p;
    p.name = "000" + std::to_string(i) + ".jpg";
    p.index = i * 8;
    p.held_out = i == 0;
    p.metrics.width = 32;
    p.metrics.height = 24;
    p.metrics.covered_pixels = 700;
    p.metrics.completeness = 700.0 / 768;
    p.metrics.error = error;
    p.metrics.error_plain = 2 * error;
    p.metrics.psnr_db = 27.5;
    p.metrics.ssim = 0.8;
    p.photo = Image8(32, 24, 3, 120);
    p.render = Image8(32, 24, 3, 110);
    p.error_map = ImageF(32, 24, 1, static_cast<float>(error));
    p.depth.available = true;
    p.depth.pixels = 600;
    p.depth.median_relative_error = 0.0123;
    p.depth.within_tolerance = 0.9;
    e.photos.push_back(std::move(p));
    e.error_histogram[static_cast<int>(error * 256)] += 700;
    e.total_pixels += 768;
  }
  e.mean_error = error;
  e.mean_completeness = 700.0 / 768;
  e.mean_psnr_db = 27.5;
  e.mean_ssim = 0.8;
  e.mean_psnr_filled_db = 21.25;
  e.mean_ssim_filled = 0.625;
  e.has_depth = true;
  e.mean_depth_median_rel = 0.0123;
  e.mean_depth_within = 0.9;
  return e;
}

TEST(ReportTest, HtmlIsSelfContainedAndHoldsTheTables) {
  const std::vector<PhotoModelEvaluation> evals = {MakeEvaluation("full", 0.04),
                                                   MakeEvaluation("no-near-envelope", 0.07)};
  ReportOptions options;
  options.references = {{"LLFF", 23.22, 0.753}};
  const std::string html = RenderHtmlReport("captures/fern", evals, options);
  // Nothing is fetched: no URL with a scheme, no external stylesheet or script.
  EXPECT_FALSE(std::regex_search(html, std::regex("https?:", std::regex::icase)));
  EXPECT_EQ(html.find("<link"), std::string::npos);
  EXPECT_EQ(html.find("<script src"), std::string::npos);
  // Table rows of both 3D photos, the ablation table and the plot.
  EXPECT_NE(html.find("<td class=\"l\">0000.jpg</td><td>0</td><td>yes</td>"), std::string::npos);
  EXPECT_NE(html.find("<td class=\"l\">0001.jpg</td><td>8</td><td>no</td>"), std::string::npos);
  EXPECT_NE(html.find("Ablation comparison"), std::string::npos);
  EXPECT_NE(html.find("<td class=\"l\">no-near-envelope</td><td>2</td><td>0.0700</td>"),
            std::string::npos);
  // Whole-frame figures and the stage timings side by side, then the
  // published reference.
  EXPECT_NE(html.find("<td>21.25</td><td>0.625</td>"), std::string::npos);
  EXPECT_NE(html.find("<th>sparse (s)</th><th>dense (s)</th>"), std::string::npos);
  EXPECT_NE(html.find("<td>12.5</td><td>40.2</td></tr>"), std::string::npos);
  EXPECT_NE(html.find("<i>LLFF</i> (published)"), std::string::npos);
  EXPECT_NE(html.find("<td>23.22</td><td>0.753</td>"), std::string::npos);
  EXPECT_NE(html.find("<svg"), std::string::npos);
  EXPECT_NE(html.find("<polyline"), std::string::npos);
  EXPECT_NE(html.find("0.0123"), std::string::npos);  // Depth error column.
  EXPECT_NE(html.find("<td class=\"l\">dense</td><td>40.25</td>"), std::string::npos);
  // Two 3D photos x two photos x three images, all embedded PNGs.
  size_t count = 0;
  for (size_t pos = 0;
       (pos = html.find("src=\"data:image/png;base64,iVBORw0KGgo", pos)) != std::string::npos;
       ++pos)
    ++count;
  EXPECT_EQ(count, 12u);
}

TEST(ReportTest, SingleEvaluationHasNoAblationTable) {
  const std::string html = RenderHtmlReport("c", {MakeEvaluation("full", 0.04)});
  EXPECT_EQ(html.find("Ablation comparison"), std::string::npos);
}

TEST(ReportTest, JsonCarriesThePerPhotoFigures) {
  const nlohmann::json j = nlohmann::json::parse(
      RenderJsonReport("c", {MakeEvaluation("full", 0.04)}, EvaluateOptions()));
  ASSERT_EQ(j["photo3d"].size(), 1u);
  const auto& photos = j["photo3d"][0]["photos"];
  ASSERT_EQ(photos.size(), 2u);
  EXPECT_EQ(photos[1]["index"], 8);
  EXPECT_DOUBLE_EQ(photos[0]["psnr_db"].get<double>(), 27.5);
  EXPECT_DOUBLE_EQ(photos[0]["depth"]["median_relative_error"].get<double>(), 0.0123);
  EXPECT_EQ(j["options"]["width"], 900);
  EXPECT_DOUBLE_EQ(j["photo3d"][0]["mean"]["psnr_filled_db"].get<double>(), 21.25);
}

TEST(ReportTest, RejectsAReferenceWithoutFigures) {
  ReportOptions options;
  options.references = {{"NeRF", 0.0, 0.792}};
  EXPECT_EQ(options.Check().message(),
            "references 'NeRF' needs a name, a PSNR in (0, 1000) dB and an SSIM in [-1, 1]");
  EXPECT_THROW(RenderHtmlReport("c", {MakeEvaluation("full", 0.04)}, options),
               std::invalid_argument);
}

TEST(ReportOptionsTest, CheckNamesTheFieldAndItsRange) {
  ReportOptions options;
  EXPECT_TRUE(options.Check().ok());
  options.thumbnail_width = 16;
  EXPECT_EQ(options.Check().message(), "thumbnail_width 16 outside [32, 2048]");
  options.thumbnail_width = 300;
  options.heatmap_max_error = 0;
  EXPECT_EQ(options.Check().message(), "heatmap_max_error 0 outside (0, 1]");
}

TEST(ReportOptionsTest, EveryFieldButTheReferenceListIsDescribed) {
  // `references` is a list, which options_fields.h does not describe.
  EXPECT_EQ(util::DescribedFieldCount<ReportOptions>() + 1,
            util::AggregateFieldCount<ReportOptions>());
}

TEST(ReportTest, Base64MatchesRfc4648Vectors) {
  EXPECT_EQ(Base64(""), "");
  EXPECT_EQ(Base64("f"), "Zg==");
  EXPECT_EQ(Base64("fo"), "Zm8=");
  EXPECT_EQ(Base64("foo"), "Zm9v");
  EXPECT_EQ(Base64("foobar"), "Zm9vYmFy");
}

TEST(ReportTest, HeatmapIsDarkForLowErrorAndGreyWhereUncovered) {
  uint8_t low[3], high[3], none[3];
  HeatmapColor(0.0f, 0.25, low);
  HeatmapColor(0.3f, 0.25, high);
  HeatmapColor(-1.0f, 0.25, none);
  EXPECT_LT(low[0] + low[1] + low[2], 100);
  EXPECT_GT(high[0] + high[1] + high[2], 600);
  EXPECT_EQ(none[0], 128);
}

}  // namespace
}  // namespace casual3d::eval
