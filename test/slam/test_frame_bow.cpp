// The BoW vector of a frame (computeBow) is made of its static keypoints only: relocalisation and
// loop candidates are keyframes that saw the same room, not the same people. A frame of a crowd
// whose screening dropped most of its keypoints must look like the keyframes of its room.
#include "yolo_slam/common/paths.h"
#include "yolo_slam/slam/frame.h"
#include "yolo_slam/vocabulary/vocabulary.h"

#include <gtest/gtest.h>

#include <random>
#include <set>

using namespace yolo_slam;
using namespace yolo_slam::slam;

namespace {

std::shared_ptr<const vocabulary::Vocabulary> shippedVocabulary() {
  return vocabulary::Vocabulary::load(packageDir() + "/vocab/yolo_slam_orb_k10_L4.vocab");
}

cv::Mat randomDescriptors(int n, unsigned seed) {
  std::mt19937 rng(seed);
  cv::Mat d(n, 32, CV_8U);
  for (int r = 0; r < n; ++r)
    for (int b = 0; b < 32; ++b) d.at<uint8_t>(r, b) = static_cast<uint8_t>(rng());
  return d;
}

// A frame of `room` (static keypoints) and `people` (dynamic ones), interleaved so that the
// dynamic flags are not one block.
Frame makeFrame(const cv::Mat& room, const cv::Mat& people, long id) {
  features::FeatureFrame ff;
  ff.width = 640;
  ff.height = 480;
  ff.descriptors = cv::Mat(0, 32, CV_8U);
  std::mt19937 rng(static_cast<unsigned>(id));
  std::uniform_real_distribution<float> ux(10.f, 630.f), uy(10.f, 470.f);
  auto add = [&](const cv::Mat& d, int row, bool dynamic) {
    cv::KeyPoint kp(cv::Point2f(ux(rng), uy(rng)), 31.f);
    kp.octave = 0;
    ff.keypoints.push_back(kp);
    ff.descriptors.push_back(d.row(row));
    ff.depth.push_back(2.f);
    ff.right_u.push_back(kp.pt.x - static_cast<float>(CameraModel().bf / 2.0));
    ff.dynamic.push_back(dynamic ? 1 : 0);
  };
  for (int k = 0; k < std::max(room.rows, people.rows); ++k) {
    if (k < room.rows) add(room, k, false);
    if (k < people.rows) add(people, k, true);
  }
  ff.keypoints_un = ff.keypoints;
  CameraModel cam;
  auto pyr = std::make_shared<ScalePyramid>(ScalePyramid::make(8, 1.2));
  return Frame(ff, cam, FrameGeometry::make(cam), pyr, id);
}

}  // namespace

TEST(FrameBow, LeavesOutTheDynamicKeypoints) {
  const auto voc = shippedVocabulary();
  ASSERT_TRUE(voc);
  Frame f = makeFrame(randomDescriptors(150, 1), randomDescriptors(400, 2), 1);
  computeBow(voc.get(), f);
  ASSERT_FALSE(f.bow.empty());

  // The direct index holds static keypoints, each once (the vocabulary leaves out those whose
  // word weighs nothing), and no dynamic one.
  std::multiset<unsigned> indexed;
  for (const auto& node : f.bow.features) indexed.insert(node.second.begin(), node.second.end());
  int statics = 0;
  for (int i = 0; i < f.N; ++i) statics += f.dynamic[i] ? 0 : 1;
  for (unsigned i : indexed) {
    ASSERT_LT(i, static_cast<unsigned>(f.N));
    EXPECT_FALSE(f.dynamic[i]) << "keypoint " << i;
    EXPECT_EQ(indexed.count(i), 1u) << "keypoint " << i;
  }
  EXPECT_GT(static_cast<int>(indexed.size()), statics / 2);

  // The BoW vector is that of the static descriptors alone.
  vocabulary::BowVector room_only;
  voc->transform(randomDescriptors(150, 1), room_only);
  EXPECT_NEAR(vocabulary::Vocabulary::score(f.bow.bow, room_only), 1.0, 1e-9);
}

TEST(FrameBow, ACrowdedFrameLooksLikeItsRoomNotItsPeople) {
  const auto voc = shippedVocabulary();
  ASSERT_TRUE(voc);
  const cv::Mat room = randomDescriptors(150, 10), other_room = randomDescriptors(150, 11);
  const cv::Mat crowd = randomDescriptors(600, 20), other_crowd = randomDescriptors(600, 21);
  Frame now = makeFrame(room, crowd, 1);           // the room behind the crowd
  Frame same_room = makeFrame(room, other_crowd, 2);  // a keyframe of the room, other people
  Frame same_crowd = makeFrame(other_room, crowd, 3);  // the same people elsewhere
  for (Frame* f : {&now, &same_room, &same_crowd}) computeBow(voc.get(), *f);
  const double room_score = vocabulary::Vocabulary::score(now.bow.bow, same_room.bow.bow);
  const double crowd_score = vocabulary::Vocabulary::score(now.bow.bow, same_crowd.bow.bow);
  EXPECT_GT(room_score, 0.99);
  EXPECT_LT(crowd_score, room_score / 2);
}

TEST(FrameBow, AFrameWithoutStaticKeypointsHasNoBow) {
  const auto voc = shippedVocabulary();
  ASSERT_TRUE(voc);
  Frame f = makeFrame(cv::Mat(0, 32, CV_8U), randomDescriptors(100, 3), 1);
  computeBow(voc.get(), f);
  EXPECT_TRUE(f.bow.empty());
  EXPECT_TRUE(f.bow.features.empty());
}
