// What the type checker and lowering share: both walk the program the way it runs, inlining every call
// (functions are generic and may take functions, so a body is checked and lowered per call). This base
// holds the frames of scopes, the call stack with its depth limit and recursion check, and the notes
// that place an error inside a body at the calls that led there.
#pragma once

#include "frontend/ast.hpp"

#include <fmt/format.h>
#include <string>
#include <utility>
#include <vector>

namespace frac::front {

// Where an expression is checked or lowered: what it may use.
enum class Context { shape, constant, test };

template <class Value>
class Inliner {
protected:
    using Scope = std::vector<std::pair<std::string, Value>>;

    struct Frame {
        Context ctx;
        std::vector<Scope> scopes;
        int level = 0; // series nesting (lowering numbers the series levels)
    };

    explicit Inliner(int max_depth) : max_depth_(max_depth) {}

    // Runs `body` in a fresh frame of its own (a constant, a test expression, a box).
    template <class F>
    Value in_closed_frame(Context ctx, F&& body) {
        frames_.push_back(Frame{ctx, {Scope{}}, 0});
        struct Pop {
            std::vector<Frame>& f;
            ~Pop() { f.pop_back(); }
        } pop{frames_};
        return body();
    }

    // Runs `body` (the inlined body of `item`, null for an anonymous function) in `frame`. An error in the
    // body gets a note at the call (`call_note`, unless empty).
    template <class F>
    Value in_call_frame(Frame frame, const Item* item, Location call_loc, const std::string& call_note,
                        F&& body) {
        if (item)
            for (const Item* active : call_stack_)
                if (active == item)
                    throw CompileError(call_loc,
                                       fmt::format("recursive call of '{}': functions are inlined, so "
                                                   "recursion is not supported (write a series instead)",
                                                   item->name));
        if (static_cast<int>(call_stack_.size()) >= max_depth_)
            throw CompileError(call_loc, fmt::format("calls nested deeper than the limit of {}{}", max_depth_,
                                                     raised_by("FRAC_MAX_CALL_DEPTH")));
        frames_.push_back(std::move(frame));
        call_stack_.push_back(item);
        struct Pop {
            std::vector<Frame>& f;
            std::vector<const Item*>& s;
            ~Pop() {
                f.pop_back();
                s.pop_back();
            }
        } pop{frames_, call_stack_};
        try {
            return body();
        } catch (CompileError& e) {
            constexpr std::size_t max_call_notes = 8;
            if (!call_note.empty() && e.notes.size() < max_call_notes)
                e.notes.emplace_back(call_loc, call_note);
            throw;
        }
    }

    // The note at a call of `it`; none for a shape's own definition, which is no call.
    static std::string call_note(const Item& it, Location call_loc) {
        const bool is_call = call_loc.line != it.loc.line || call_loc.column != it.loc.column;
        return is_call ? fmt::format("in this call of '{}'", it.name) : std::string();
    }

    // `let a = ..., b = ... in body`: each binding sees the ones before it.
    template <class Eval>
    Value let(const Expr& e, Eval&& eval) {
        frames_.back().scopes.emplace_back();
        for (const Binding& b : e.bindings) {
            Value v = eval(*b.value);
            frames_.back().scopes.back().emplace_back(b.name, std::move(v));
        }
        Value body = eval(*e.kids[0]);
        frames_.back().scopes.pop_back();
        return body;
    }

    const Value* lookup_local(const std::string& name) const {
        const Frame& f = frames_.back();
        for (auto s = f.scopes.rbegin(); s != f.scopes.rend(); ++s)
            for (auto b = s->rbegin(); b != s->rend(); ++b)
                if (b->first == name) return &b->second;
        return nullptr;
    }

    std::vector<Frame> frames_;
    std::vector<const Item*> call_stack_;

private:
    int max_depth_;
};

} // namespace frac::front
