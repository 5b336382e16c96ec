// handle.h — move-only RAII owner of one Vulkan handle. The deleter is a callable that
// receives the handle; it is called exactly once, when the owner dies or is reset.
#pragma once

#include <functional>
#include <utility>

namespace gdpt::vk {

template <typename T>
class Handle {
public:
    Handle() = default;
    Handle(T handle, std::function<void(T)> deleter) : handle_(handle), deleter_(std::move(deleter)) {}
    ~Handle() { reset(); }
    Handle(const Handle&) = delete;
    Handle& operator=(const Handle&) = delete;
    Handle(Handle&& other) noexcept { swap(other); }
    Handle& operator=(Handle&& other) noexcept {
        if (this != &other) {
            reset();
            swap(other);
        }
        return *this;
    }
    void reset() {
        if (handle_ != T{} && deleter_) deleter_(handle_);
        handle_ = T{};
        deleter_ = nullptr;
    }
    [[nodiscard]] T get() const { return handle_; }
    [[nodiscard]] explicit operator bool() const { return handle_ != T{}; }

private:
    void swap(Handle& other) noexcept {
        std::swap(handle_, other.handle_);
        std::swap(deleter_, other.deleter_);
    }
    T handle_{};
    std::function<void(T)> deleter_;
};

}  // namespace gdpt::vk
