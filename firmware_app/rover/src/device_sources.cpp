#include "sunvo/rover/device_sources.hpp"

#include <algorithm>

#include "sunvo/kitti/calibration.hpp"
#include "sunvo/rover/sun_provider.hpp"

namespace sunvo::rover {

Expected<std::unique_ptr<StrobeTrigger>> StrobeTrigger::open(const TriggerConfig& config,
                                                             TimeNs wait_timeout_ns,
                                                             gpio::GpioApi& api,
                                                             TimeNs utc_minus_mono_ns) {
  gpio::StrobeInputOptions o;
  o.gpio.chip = config.gpio_chip;
  o.gpio.line = config.gpio_line;
  o.gpio.consumer = "sunvo-strobe";
  o.wait_timeout_ms = static_cast<int>(std::clamp<TimeNs>(wait_timeout_ns / 1'000'000, 1, 60000));
  const Status v = o.validate();
  if (!v.isOk()) return Status(v.code(), "trigger: " + v.message());
  auto input = gpio::StrobeInput::open(o, api);
  if (!input) return Status(input.status().code(), "trigger.gpio: " + input.status().message());
  std::unique_ptr<StrobeTrigger> t(new StrobeTrigger());
  t->input_ = std::move(*input);
  t->utc_minus_mono_ns_ = utc_minus_mono_ns;
  return t;
}

Status StrobeTrigger::wait(TimeNs /*timeout_ns*/, TriggerEvent* out) {
  auto edge = input_->next();
  if (!edge) return edge.status();  // kTimeout: no strobe; kDeviceError names chip and line
  out->sequence = edge->sequence;
  out->mono_ns = edge->time_ns;
  out->utc_ns = edge->time_ns + utc_minus_mono_ns_;
  return Status::ok();
}

Expected<std::unique_ptr<V4l2FrameSource>> V4l2FrameSource::open(const RoverConfig& config,
                                                                 sysio::SysIo& io,
                                                                 TimeNs utc_minus_mono_ns) {
  const V4l2SourceConfig& c = config.source.v4l2;
  if (c.calibration.empty()) return invalidArgument("source.v4l2.calibration: empty");
  const auto format = calib::detectFormat(c.calibration, c.calibration_format);
  if (!format) {
    return Status(format.status().code(), "source.v4l2.calibration: " + format.status().message());
  }
  StereoCamera camera;
  std::unique_ptr<calib::StereoRectifier> rectifier;
  if (*format == calib::CalibrationFormat::kKitti) {
    auto c2c = kitti::readCamToCam(c.calibration);
    if (!c2c)
      return Status(c2c.status().code(), "source.v4l2.calibration: " + c2c.status().message());
    auto rect = kitti::rawStereoCamera(*c2c, 0, 1);
    if (!rect) {
      return Status(rect.status().code(), "source.v4l2.calibration: " + rect.status().message());
    }
    camera = *rect;
  } else {
    auto raw = calib::readRawStereoCalibration(c.calibration, *format);
    if (!raw)
      return Status(raw.status().code(), "source.v4l2.calibration: " + raw.status().message());
    if (raw->size != cv::Size(config.frames.width, config.frames.height)) {
      return invalidArgument(
          "source.v4l2.calibration: " + c.calibration + ": image size " +
          std::to_string(raw->size.width) + "x" + std::to_string(raw->size.height) +
          " differs from frames.width/height " + std::to_string(config.frames.width) + "x" +
          std::to_string(config.frames.height));
    }
    auto r = calib::StereoRectifier::create(*raw, c.rectify);
    if (!r) return Status(r.status().code(), "source.v4l2.calibration: " + r.status().message());
    rectifier = std::move(*r);
    camera = rectifier->camera();
  }

  v4l2::V4l2Options vo;
  vo.layout = c.layout;
  vo.left_device = c.left_device;
  vo.right_device = c.right_device;
  vo.pixel_format = c.pixel_format;
  // Colour only for a provider that looks at images (the frame pool has colour slots then).
  const bool colour = c.left_color && sunProviderNeedsImages(config.sun.provider);
  vo.left_color = colour;
  vo.width = config.frames.width;
  vo.height = config.frames.height;
  vo.fps = config.trigger.rate_hz;
  vo.buffer_count = c.buffer_count;
  vo.dequeue_timeout_ms = c.dequeue_timeout_ms;
  auto cam = v4l2::V4l2StereoSource::open(vo, io);
  if (!cam) return Status(cam.status().code(), "source.v4l2: " + cam.status().message());

  gpio::TriggerPairerOptions po;
  po.frame_period_ns = static_cast<TimeNs>(1e9 / config.trigger.rate_hz);
  po.expected_delay_ns = static_cast<TimeNs>(config.trigger.frame_delay_ms * 1e6);
  po.match_window_ns = static_cast<TimeNs>(config.trigger.match_window_ms * 1e6);
  auto pairer = gpio::TriggerPairer::create(po);
  if (!pairer) return Status(pairer.status().code(), "trigger: " + pairer.status().message());

  std::unique_ptr<V4l2FrameSource> s(new V4l2FrameSource());
  s->camera_ = camera;
  if (rectifier) {
    // The camera's frame before rectification, allocated here so grab() allocates nothing.
    const cv::Size size(config.frames.width, config.frames.height);
    s->raw_.left.create(size, CV_8UC1);
    s->raw_.right.create(size, CV_8UC1);
    if (colour) s->raw_.left_color.create(size, CV_8UC3);
    s->rectifier_ = std::move(rectifier);
  }
  s->camera_source_ = std::move(*cam);
  s->pairer_ = std::make_unique<gpio::TriggerPairer>(std::move(*pairer));
  s->utc_minus_mono_ns_ = utc_minus_mono_ns;
  s->max_reads_ = c.buffer_count + 1;
  return s;
}

Status V4l2FrameSource::grab(const TriggerEvent& trigger, runtime::FrameSlot& slot) {
  pairer_->addTrigger(gpio::TriggerEvent{trigger.sequence, trigger.mono_ns});
  StereoFrame& frame = slot.frame;
  const TimeNs delay_ns = pairer_->options().expected_delay_ns;
  const TimeNs window_ns = pairer_->options().match_window_ns;
  for (int read = 0; read < max_reads_; ++read) {
    // Rectified frames go straight into the slot's Mats; raw ones into raw_ first.
    SUNVO_RETURN_IF_ERROR(camera_source_->next(rectifier_ ? raw_ : frame));
    const TimeNs frame_ns = camera_source_->lastPair().left_time_ns;
    const std::optional<gpio::TriggerEvent> paired = pairer_->matchFrame(frame_ns);
    if (paired) {
      if (rectifier_) SUNVO_RETURN_IF_ERROR(rectifier_->rectify(raw_, frame));
      frame.sequence = trigger.sequence;
      frame.trigger_time_ns = paired->time_ns + utc_minus_mono_ns_;
      slot.meta.source_index = camera_source_->lastPair().left_sequence;
      return Status::ok();
    }
    // No strobe for this frame. Exposed before this trigger (its strobe was lost): skip it and
    // read the next one. Exposed after it: this trigger has no frame.
    if (frame_ns - delay_ns > trigger.mono_ns + window_ns) break;
  }
  return notFound("source.v4l2: no frame paired with strobe " + std::to_string(trigger.sequence));
}

}  // namespace sunvo::rover
