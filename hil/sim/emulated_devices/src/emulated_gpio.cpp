#include "sunvo/emulated/emulated_gpio.hpp"

#include <cerrno>
#include <chrono>

#include "sunvo/sysio/sysio.hpp"

namespace sunvo::emulated {
namespace {}  // namespace

struct EmulatedGpio::Line {
  enum class Mode { kFree, kOutput, kEvents };
  Chip* chip = nullptr;
  int offset = 0;
  Mode mode = Mode::kFree;
  std::string consumer;
  int value = 0;
  std::vector<GpioWrite> writes;
  std::deque<gpio::LineEvent> events;
  int drop_strobes = 0;
  int duplicate_strobes = 0;
  TimeNs duplicate_gap_ns = 0;
  int fail_err = 0;
  OutputListener listener;
};

struct EmulatedGpio::Chip {
  std::string name;
  std::vector<std::unique_ptr<Line>> lines;
  int open_count = 0;
};

EmulatedGpio::EmulatedGpio() = default;
EmulatedGpio::~EmulatedGpio() = default;

Status EmulatedGpio::addChip(const std::string& name, int num_lines) {
  std::lock_guard lock(mutex_);
  if (num_lines < 1) return invalidArgument("gpio chip " + name + ": no lines");
  for (const auto& c : chips_) {
    if (c->name == name) return invalidArgument("gpio chip " + name + " exists");
  }
  auto chip = std::make_unique<Chip>();
  chip->name = name;
  for (int i = 0; i < num_lines; ++i) {
    auto l = std::make_unique<Line>();
    l->chip = chip.get();
    l->offset = i;
    chip->lines.push_back(std::move(l));
  }
  chips_.push_back(std::move(chip));
  return Status::ok();
}

EmulatedGpio::Line* EmulatedGpio::findLine(const std::string& chip, int line) const {
  for (const auto& c : chips_) {
    if (c->name == chip && line >= 0 && line < static_cast<int>(c->lines.size())) {
      return c->lines[static_cast<std::size_t>(line)].get();
    }
  }
  return nullptr;
}

int EmulatedGpio::takeFault(Line& l) {
  const int err = l.fail_err;
  l.fail_err = 0;
  return err;
}

Status EmulatedGpio::withLine(const std::string& chip, int line,
                              const std::function<void(Line&)>& change) {
  {
    std::lock_guard lock(mutex_);
    Line* l = findLine(chip, line);
    if (l == nullptr) {
      return invalidArgument("no emulated gpio " + chip + " line " + std::to_string(line));
    }
    change(*l);
  }
  changed_.notify_all();
  return Status::ok();
}

Status EmulatedGpio::pushEdge(const std::string& chip, int line, TimeNs time_ns, bool rising) {
  return withLine(chip, line, [&](Line& l) {
    if (l.mode == Line::Mode::kEvents) l.events.push_back({time_ns, rising});
  });
}

Status EmulatedGpio::strobe(const std::string& chip, int line, TimeNs time_ns, TimeNs width_ns) {
  return withLine(chip, line, [&](Line& l) {
    if (l.drop_strobes > 0) {
      --l.drop_strobes;
      return;
    }
    if (l.mode != Line::Mode::kEvents) return;
    l.events.push_back({time_ns, true});
    l.events.push_back({time_ns + width_ns, false});
    if (l.duplicate_strobes > 0) {
      --l.duplicate_strobes;
      l.events.push_back({time_ns + l.duplicate_gap_ns, true});
      l.events.push_back({time_ns + l.duplicate_gap_ns + width_ns, false});
    }
  });
}

Status EmulatedGpio::dropStrobes(const std::string& chip, int line, int count) {
  return withLine(chip, line, [&](Line& l) { l.drop_strobes += count; });
}

Status EmulatedGpio::duplicateStrobes(const std::string& chip, int line, int count, TimeNs gap_ns) {
  return withLine(chip, line, [&](Line& l) {
    l.duplicate_strobes += count;
    l.duplicate_gap_ns = gap_ns;
  });
}

Status EmulatedGpio::failNextCall(const std::string& chip, int line, int err) {
  return withLine(chip, line, [&](Line& l) { l.fail_err = err; });
}

Status EmulatedGpio::onOutput(const std::string& chip, int line, OutputListener listener) {
  return withLine(chip, line, [&](Line& l) { l.listener = std::move(listener); });
}

std::vector<GpioWrite> EmulatedGpio::writes(const std::string& chip, int line) const {
  std::lock_guard lock(mutex_);
  const Line* l = findLine(chip, line);
  return l != nullptr ? l->writes : std::vector<GpioWrite>{};
}

int EmulatedGpio::value(const std::string& chip, int line) const {
  std::lock_guard lock(mutex_);
  const Line* l = findLine(chip, line);
  return l != nullptr ? l->value : 0;
}

bool EmulatedGpio::requested(const std::string& chip, int line) const {
  std::lock_guard lock(mutex_);
  const Line* l = findLine(chip, line);
  return l != nullptr && l->mode != Line::Mode::kFree;
}

int EmulatedGpio::openChips() const {
  std::lock_guard lock(mutex_);
  int n = 0;
  for (const auto& c : chips_) n += c->open_count;
  return n;
}

int EmulatedGpio::chipOpen(const char* name_or_path, gpio::ChipHandle& chip) {
  std::lock_guard lock(mutex_);
  const std::string wanted(name_or_path);
  for (const auto& c : chips_) {
    if (wanted == c->name || wanted == "/dev/" + c->name) {
      ++c->open_count;
      chip.impl = c.get();
      return 0;
    }
  }
  return ENOENT;
}

void EmulatedGpio::chipClose(gpio::ChipHandle chip) {
  {
    std::lock_guard lock(mutex_);
    auto* c = static_cast<Chip*>(chip.impl);
    if (c == nullptr) return;
    --c->open_count;
    for (auto& l : c->lines) {
      l->mode = Line::Mode::kFree;
      l->events.clear();
    }
  }
  changed_.notify_all();
}

int EmulatedGpio::chipGetLine(gpio::ChipHandle chip, unsigned offset, gpio::LineHandle& line) {
  std::lock_guard lock(mutex_);
  auto* c = static_cast<Chip*>(chip.impl);
  if (c == nullptr || c->open_count <= 0) return EBADF;
  if (offset >= c->lines.size()) return EINVAL;
  line.impl = c->lines[offset].get();
  return 0;
}

int EmulatedGpio::request(gpio::LineHandle line, const char* consumer, bool output,
                          int default_value) {
  std::lock_guard lock(mutex_);
  auto& l = *static_cast<Line*>(line.impl);
  if (const int err = takeFault(l); err != 0) return err;
  if (l.mode != Line::Mode::kFree) return EBUSY;
  l.consumer = consumer;
  if (output) {
    l.mode = Line::Mode::kOutput;
    l.value = default_value != 0 ? 1 : 0;
    l.writes.push_back({l.value, sysio::monotonicNowNs()});
  } else {
    l.mode = Line::Mode::kEvents;
    l.events.clear();
  }
  return 0;
}

int EmulatedGpio::lineRequestOutput(gpio::LineHandle line, const char* consumer,
                                    int default_value) {
  return request(line, consumer, true, default_value);
}

int EmulatedGpio::lineRequestBothEdgesEvents(gpio::LineHandle line, const char* consumer) {
  return request(line, consumer, false, 0);
}

int EmulatedGpio::lineSetValue(gpio::LineHandle line, int value) {
  OutputListener listener;
  GpioWrite write;
  {
    std::lock_guard lock(mutex_);
    auto& l = *static_cast<Line*>(line.impl);
    if (const int err = takeFault(l); err != 0) return err;
    if (l.mode != Line::Mode::kOutput) return EPERM;
    l.value = value != 0 ? 1 : 0;
    write = {l.value, sysio::monotonicNowNs()};
    l.writes.push_back(write);
    listener = l.listener;
  }
  if (listener) listener(write.value, write.time_ns);
  return 0;
}

int EmulatedGpio::lineEventWait(gpio::LineHandle line, TimeNs timeout_ns, bool& ready) {
  std::unique_lock lock(mutex_);
  auto& l = *static_cast<Line*>(line.impl);
  if (const int err = takeFault(l); err != 0) return err;
  if (l.mode != Line::Mode::kEvents) return EPERM;
  ready = changed_.wait_for(lock, std::chrono::nanoseconds(timeout_ns), [&] {
    return !l.events.empty() || l.mode != Line::Mode::kEvents || l.fail_err != 0;
  });
  if (const int err = takeFault(l); err != 0) return err;
  if (l.mode != Line::Mode::kEvents) return EPERM;
  ready = !l.events.empty();
  return 0;
}

int EmulatedGpio::lineEventRead(gpio::LineHandle line, gpio::LineEvent& event) {
  std::lock_guard lock(mutex_);
  auto& l = *static_cast<Line*>(line.impl);
  if (const int err = takeFault(l); err != 0) return err;
  if (l.mode != Line::Mode::kEvents) return EPERM;
  if (l.events.empty()) return EAGAIN;
  event = l.events.front();
  l.events.pop_front();
  return 0;
}

void EmulatedGpio::lineRelease(gpio::LineHandle line) {
  {
    std::lock_guard lock(mutex_);
    auto& l = *static_cast<Line*>(line.impl);
    l.mode = Line::Mode::kFree;
    l.events.clear();
  }
  changed_.notify_all();
}

}  // namespace sunvo::emulated
