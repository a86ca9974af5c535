// Small evaluators for the runtime tests, written directly with the numeric core's interval ops, so
// the runtime is tested without the frontend or a backend.
#pragma once

#include "ir/evaluator.hpp"
#include "numeric/interval.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

namespace frac::rt::test {

using num::Interval;

// Common part: records how the batch API is used.
class TestShape : public ir::Evaluator {
public:
    explicit TestShape(int dim) : dim_(dim) {}
    int dimension() const override { return dim_; }
    std::string engine() const override { return "test"; }
    void eval_boxes(const Interval* boxes, std::size_t n, Interval* out) override {
        ++batches;
        max_batch = std::max(max_batch, n);
        Evaluator::eval_boxes(boxes, n, out);
    }

    std::size_t batches = 0, max_batch = 0;

private:
    int dim_;
};

// (x-cx)^2 + (y-cy)^2 - r^2: sqr and + of independent variables give the exact range, up to rounding.
class Disk : public TestShape {
public:
    Disk(double cx, double cy, double r) : TestShape(2), cx(cx), cy(cy), r(r) {}
    double eval_point(const double* p) override {
        const double dx = p[0] - cx, dy = p[1] - cy;
        return dx * dx + dy * dy - r * r;
    }
    Interval eval_box(const Interval* b) override {
        num::UpwardRounding up;
        const Interval dx = num::sub(b[0], Interval(cx)), dy = num::sub(b[1], Interval(cy));
        return num::sub(num::add(num::sqr(dx), num::sqr(dy)), num::sqr(Interval(r)));
    }
    std::unique_ptr<Evaluator> clone() const override { return std::make_unique<Disk>(*this); }

    double cx, cy, r;
};

// x^2 + y^2 + z^2 - r^2.
class Ball : public TestShape {
public:
    explicit Ball(double r) : TestShape(3), r(r) {}
    double eval_point(const double* p) override { return p[0] * p[0] + p[1] * p[1] + p[2] * p[2] - r * r; }
    Interval eval_box(const Interval* b) override {
        num::UpwardRounding up;
        const Interval s = num::add(num::add(num::sqr(b[0]), num::sqr(b[1])), num::sqr(b[2]));
        return num::sub(s, num::sqr(Interval(r)));
    }
    std::unique_ptr<Evaluator> clone() const override { return std::make_unique<Ball>(*this); }

    double r;
};

// a*x + b*y + c: inside where negative.
class HalfPlane : public TestShape {
public:
    HalfPlane(double a, double b, double c) : TestShape(2), a(a), b(b), c(c) {}
    double eval_point(const double* p) override { return a * p[0] + b * p[1] + c; }
    Interval eval_box(const Interval* box) override {
        num::UpwardRounding up;
        return num::add(num::add(num::mul(Interval(a), box[0]), num::mul(Interval(b), box[1])), Interval(c));
    }
    std::unique_ptr<Evaluator> clone() const override { return std::make_unique<HalfPlane>(*this); }

    double a, b, c;
};

// 1/4 - dz(freq * x): vertical stripes, inside where freq*x is within 1/4 of a half-integer.
class Stripes : public TestShape {
public:
    explicit Stripes(double freq) : TestShape(2), freq(freq) {}
    double eval_point(const double* p) override { return 0.25 - num::point::dz(freq * p[0]); }
    Interval eval_box(const Interval* b) override {
        num::UpwardRounding up;
        return num::sub(Interval(0.25), num::dz(num::mul(Interval(freq), b[0])));
    }
    std::unique_ptr<Evaluator> clone() const override { return std::make_unique<Stripes>(*this); }

    double freq;
};

// Undefined (empty enclosure) where x < 0 on the whole box, else x - 1/2.
class HalfDefined : public TestShape {
public:
    HalfDefined() : TestShape(2) {}
    double eval_point(const double* p) override {
        return p[0] < 0 ? std::numeric_limits<double>::quiet_NaN() : p[0] - 0.5;
    }
    Interval eval_box(const Interval* b) override {
        if (b[0].hi < 0) return Interval::empty();
        num::UpwardRounding up;
        return num::sub(Interval(std::max(b[0].lo, 0.0), b[0].hi), Interval(0.5));
    }
    std::unique_ptr<Evaluator> clone() const override { return std::make_unique<HalfDefined>(*this); }
};

// A misbehaving backend: a NaN bound everywhere. Every cell must stay undecided.
class NanShape : public TestShape {
public:
    explicit NanShape(int dim) : TestShape(dim) {}
    double eval_point(const double*) override { return std::numeric_limits<double>::quiet_NaN(); }
    Interval eval_box(const Interval*) override { return {std::numeric_limits<double>::quiet_NaN(), 1.0}; }
    std::unique_ptr<Evaluator> clone() const override { return std::make_unique<NanShape>(*this); }
};

// f = value everywhere.
class Constant : public TestShape {
public:
    Constant(int dim, double value) : TestShape(dim), value(value) {}
    double eval_point(const double*) override { return value; }
    Interval eval_box(const Interval*) override { return Interval(value); }
    std::unique_ptr<Evaluator> clone() const override { return std::make_unique<Constant>(*this); }

    double value;
};

} // namespace frac::rt::test
