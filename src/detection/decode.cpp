#include "yolo_slam/detection/decode.h"

#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <map>

namespace yolo_slam {
namespace detection {

InputTransform InputTransform::make(cv::Size image, cv::Size input, bool letterbox) {
  InputTransform t;
  t.scale_x = double(input.width) / image.width;
  t.scale_y = double(input.height) / image.height;
  if (letterbox) {
    double s = std::min(t.scale_x, t.scale_y);
    t.scale_x = t.scale_y = s;
    // Integer padding so that the resized image lands on whole pixels.
    t.pad_x = (input.width - int(std::lround(image.width * s))) / 2;
    t.pad_y = (input.height - int(std::lround(image.height * s))) / 2;
  }
  return t;
}

cv::Rect2f InputTransform::toImage(const cv::Rect2f& r) const {
  float x1 = float((r.x - pad_x) / scale_x), y1 = float((r.y - pad_y) / scale_y);
  float x2 = float((r.x + r.width - pad_x) / scale_x);
  float y2 = float((r.y + r.height - pad_y) / scale_y);
  return {x1, y1, x2 - x1, y2 - y1};
}

cv::Mat fitToInput(const cv::Mat& bgr, cv::Size input, const InputTransform& t) {
  if (t.pad_x == 0 && t.pad_y == 0) {
    cv::Mat out;
    cv::resize(bgr, out, input, 0, 0, cv::INTER_LINEAR);
    return out;
  }
  cv::Mat out(input, bgr.type(), cv::Scalar::all(114));
  cv::Size inner(int(std::lround(bgr.cols * t.scale_x)), int(std::lround(bgr.rows * t.scale_y)));
  inner.width = std::min(inner.width, input.width - int(t.pad_x));
  inner.height = std::min(inner.height, input.height - int(t.pad_y));
  cv::resize(bgr, out(cv::Rect(int(t.pad_x), int(t.pad_y), inner.width, inner.height)), inner, 0,
             0, cv::INTER_LINEAR);
  return out;
}

void decodeYoloRows(const cv::Mat& rows_in, cv::Size input, bool normalized,
                    bool class_scores_include_objectness, const std::vector<bool>& keep,
                    float conf, std::vector<Candidate>& out) {
  // Accept [N, 5+C] and [1, N, 5+C].
  cv::Mat rows = rows_in.dims == 2 ? rows_in : rows_in.reshape(1, int(rows_in.total() / rows_in.size[rows_in.dims - 1]));
  const int n_classes = rows.cols - 5;
  const float sx = normalized ? float(input.width) : 1.f;
  const float sy = normalized ? float(input.height) : 1.f;
  for (int i = 0; i < rows.rows; ++i) {
    const float* r = rows.ptr<float>(i);
    const float obj = r[4];
    if (class_scores_include_objectness ? obj <= 0.f : obj < conf) continue;
    for (int c = 0; c < n_classes && c < int(keep.size()); ++c) {
      if (!keep[c]) continue;
      float score = class_scores_include_objectness ? r[5 + c] : obj * r[5 + c];
      if (score < conf) continue;
      float w = r[2] * sx, h = r[3] * sy;
      out.push_back({c, score, cv::Rect2f(r[0] * sx - w / 2, r[1] * sy - h / 2, w, h)});
    }
  }
}

void decodeNanoDetLevel(const cv::Mat& cls_in, const cv::Mat& reg_in, int stride,
                        cv::Size input, const std::vector<bool>& keep, float conf,
                        std::vector<Candidate>& out) {
  cv::Mat cls = cls_in.reshape(1, int(cls_in.total() / cls_in.size[cls_in.dims - 1]));
  cv::Mat reg = reg_in.reshape(1, int(reg_in.total() / reg_in.size[reg_in.dims - 1]));
  const int grid_w = (input.width + stride - 1) / stride;
  const int bins = reg.cols / 4;
  std::vector<float> prob(bins);
  for (int i = 0; i < cls.rows; ++i) {
    const float* s = cls.ptr<float>(i);
    int best = -1;
    float best_score = conf;
    for (int c = 0; c < cls.cols && c < int(keep.size()); ++c)
      if (keep[c] && s[c] >= best_score) { best = c; best_score = s[c]; }
    if (best < 0) continue;
    // Each side's distance is the expectation of a softmax over `bins` integer distances.
    const float* d = reg.ptr<float>(i);
    float dist[4];
    for (int k = 0; k < 4; ++k) {
      const float* logits = d + k * bins;
      float mx = *std::max_element(logits, logits + bins), sum = 0, e = 0;
      for (int b = 0; b < bins; ++b) sum += (prob[b] = std::exp(logits[b] - mx));
      for (int b = 0; b < bins; ++b) e += b * prob[b] / sum;
      dist[k] = e * stride;
    }
    // Cell centres (NanoDet's priors sit at the centre of each stride x stride cell).
    float cx = ((i % grid_w) + 0.5f) * stride, cy = ((i / grid_w) + 0.5f) * stride;
    float x1 = cx - dist[0], y1 = cy - dist[1], x2 = cx + dist[2], y2 = cy + dist[3];
    out.push_back({best, best_score, cv::Rect2f(x1, y1, x2 - x1, y2 - y1)});
  }
}

Boxes suppressAndMap(const std::vector<Candidate>& cands, float conf, float nms,
                     const InputTransform& t, cv::Size image,
                     const std::vector<std::string>& class_names) {
  std::map<int, std::vector<int>> by_class;
  for (int i = 0; i < int(cands.size()); ++i) by_class[cands[i].class_id].push_back(i);
  const cv::Rect2f frame(0.f, 0.f, float(image.width), float(image.height));
  Boxes boxes;
  for (const auto& [cls, idx] : by_class) {
    std::vector<cv::Rect2d> rects;
    std::vector<float> scores;
    for (int i : idx) {
      rects.emplace_back(cands[i].rect);
      scores.push_back(cands[i].score);
    }
    std::vector<int> kept;
    cv::dnn::NMSBoxes(rects, scores, conf, nms, kept);
    for (int k : kept) {
      const Candidate& c = cands[idx[k]];
      cv::Rect2f r = t.toImage(c.rect) & frame;
      if (r.width <= 0 || r.height <= 0) continue;
      Box b;
      b.class_id = cls;
      b.label = cls < int(class_names.size()) ? class_names[cls] : std::to_string(cls);
      b.score = c.score;
      b.rect = r;
      boxes.push_back(b);
    }
  }
  std::sort(boxes.begin(), boxes.end(), [](const Box& a, const Box& b) { return a.score > b.score; });
  return boxes;
}

float iou(const cv::Rect2f& a, const cv::Rect2f& b) {
  float inter = (a & b).area();
  float uni = a.area() + b.area() - inter;
  return uni > 0 ? inter / uni : 0.f;
}

}  // namespace detection
}  // namespace yolo_slam
