// augocc annotate: the interactive key-frame silhouette tool (the paper's Section 5).
// A thin highgui shell over cv::augocc::SilhouetteEditor: the window forwards clicks and keys,
// the editor does the tracing, snapping, filling and undo.

#include "cli_common.hpp"
#include "window_shell.hpp"

#include <cstdlib>
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <map>
#include <set>

#include <opencv2/highgui.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/augocc.hpp>

namespace augocc_cli {

namespace {

namespace fs = std::filesystem;
using namespace cv;
using namespace cv::augocc;

const char* const kWindow = "augocc annotate";
// A click within this distance of an anchor grabs it (window pixels, whatever the zoom: about a
// fingertip on a mouse).
const double kGrabRadius = 6.0;
// One zoom key press scales the view by this.
const double kZoomStep = 1.25;
const int kStatusHeight = 46;   // two text lines under the frame
const int kTimelineHeight = 10; // key-frame ruler under the text

const char* const kHelp[][2] = {
    {"left click", "add anchor; on the first anchor: close; drag: move anchor"},
    {"right click", "close contour / delete the anchor under the cursor"},
    {"l", "toggle live wire / straight segments"},
    {"c, Enter", "close contour"},
    {"Backspace, b", "remove the last anchor"},
    {"u, z  /  r, y", "undo  /  redo"},
    {"i  /  d", "insert anchor on segment  /  delete anchor (at cursor)"},
    {"x", "clear this frame's silhouette"},
    {"g", "propose outline: from the clone (--clones) or nearest key frame"},
    {"n, .  /  p, ,", "next  /  previous frame"},
    {"]  /  [", "next  /  previous key frame"},
    {"k", "mark / unmark this frame as a key frame"},
    {"o  /  a", "next object  /  add an object"},
    {"s  /  q, Esc", "save masks  /  save and quit"},
    {"w  /  h", "save a screenshot  /  this help"},
    {"+  /  -", "zoom in  /  out about the cursor"},
    {"0  /  1", "fit the frame to the window  /  zoom 100% (1:1)"},
    {"middle drag", "pan (also Ctrl + left drag)"},
};

struct Options
{
    std::string input, masks, tracks, reconstruction, clones, screenshotDir;
    std::string maxWindow = "1600x900";
    std::vector<std::string> objects;
    int frame = 0, suggest = 0;
};

class AnnotateApp
{
public:
    AnnotateApp(const Options& o, const Globals& g, Size maxView)
        : opt_(o), g_(g), maxView_(maxView) {}

    void run()
    {
        source_ = FrameSource::open(opt_.input);
        frameCount_ = source_->count();
        frameSize_ = source_->size();
        if (frameCount_ <= 0)
            throw UsageError("--input " + opt_.input + ": no frames");
        if (fs::exists(opt_.masks))
            masks_ = readMasks(opt_.masks, frameSize_);
        for (const auto& om : masks_)
            addObject(om.first);
        for (const std::string& name : opt_.objects)
            addObject(name);
        if (objects_.empty())
            addObject("object");
        if (!opt_.objects.empty())
            object_ = indexOf(opt_.objects.front());
        if (!opt_.clones.empty())
        {
            if (opt_.reconstruction.empty())
                throw UsageError("--clones needs --reconstruction");
            rec_ = readReconstruction(opt_.reconstruction);
            if (rec_.imageSize != frameSize_)
                throw UsageError(format("--reconstruction %s: image size %dx%d, the frames are "
                                        "%dx%d", opt_.reconstruction.c_str(),
                                        rec_.imageSize.width, rec_.imageSize.height,
                                        frameSize_.width, frameSize_.height));
            clones_ = CloneSet::load(opt_.clones);
        }
        suggestKeyFrameMarks();
        if (opt_.frame < 0 || opt_.frame >= frameCount_)
            throw UsageError(format("--frame %d: the input has frames 0..%d", opt_.frame,
                                    frameCount_ - 1));
        frame_ = opt_.frame;
        loadFrame();
        requireDisplay("annotate");

        viewport_ = ImageViewport(frameSize_, ImageViewport::fitViewSize(frameSize_, maxView_));
        namedWindow(kWindow, WINDOW_AUTOSIZE | WINDOW_GUI_NORMAL);
        setMouseCallback(kWindow, &AnnotateApp::onMouse, this);
        render();
        waitKey(50);
        // Where the frame lies on the screen: tests and scripts driving the window with
        // xdotool read this line, and the view lines (the window pixel at the rectangle's
        // top-left + p shows frame point (p - offset) / scale, ImageViewport).
        logWindowImageRect(g_, "annotate", kWindow);
        logView();
        bool quit = false;
        while (!quit)
        {
            if (dirty_)
                render();
            const int key = waitKeyEx(15);
            if (key >= 0)
                quit = handleKey(key);
            else if (getWindowProperty(kWindow, WND_PROP_VISIBLE) == 0)
                quit = true;  // the window was closed
        }
        save();
        destroyAllWindows();
        waitKey(1);
    }

private:
    // ---- objects, frames, key frames --------------------------------------------------------

    void addObject(const std::string& name)
    {
        if (name.empty() || name.find('/') != std::string::npos || name[0] == '.')
            throw UsageError("--object '" + name + "': not a valid folder name");
        if (indexOf(name) < 0)
        {
            objects_.push_back(name);
            std::set<int>& marks = keyMarks_[name];
            marks.insert(0);
            marks.insert(frameCount_ - 1);
            for (const auto& fm : masks_[name])
                marks.insert(fm.first);
        }
    }

    int indexOf(const std::string& name) const
    {
        for (size_t i = 0; i < objects_.size(); ++i)
            if (objects_[i] == name)
                return int(i);
        return -1;
    }

    const std::string& objectName() const { return objects_[object_]; }

    void suggestKeyFrameMarks()
    {
        if (opt_.suggest <= 0)
            return;
        if (opt_.tracks.empty() && opt_.reconstruction.empty())
            throw UsageError("--suggest needs --tracks and/or --reconstruction");
        Tracks tracks;
        Reconstruction rec;
        if (!opt_.tracks.empty())
            tracks = readTracks(opt_.tracks);
        if (!opt_.reconstruction.empty())
            rec = readReconstruction(opt_.reconstruction);
        for (const std::string& name : objects_)
        {
            std::vector<int> keys;
            const FrameMasks& fm = masks_[name];
            if (!opt_.tracks.empty() && !opt_.reconstruction.empty())
                keys = suggestKeyFrames(tracks, rec, opt_.suggest, fm);
            else if (!opt_.tracks.empty())
                keys = suggestKeyFrames(tracks, opt_.suggest,
                                        fm.empty() ? std::vector<uchar>()
                                                   : objectTracksFromMasks(tracks, fm));
            else
                keys = suggestKeyFrames(rec, opt_.suggest);
            std::string list;
            for (int k : keys)
            {
                if (k < frameCount_)
                    keyMarks_[name].insert(k);
                list += format(" %d", k);
            }
            info(g_, "annotate: suggested key frames for " + name + ":" + list);
        }
    }

    void loadFrame()
    {
        source_->seek(frame_);
        if (!source_->read(image_) || image_.empty())
            throw UsageError(format("--input %s: cannot read frame %d", opt_.input.c_str(),
                                    frame_));
        editor_ = editorFor(object_, frame_);
        dirty_ = true;
    }

    // One editor per (object, frame) visited, so that going back to a frame keeps its open
    // contour and its undo history.
    Ptr<SilhouetteEditor> editorFor(int object, int frame)
    {
        auto key = std::make_pair(object, frame);
        auto it = editors_.find(key);
        if (it != editors_.end())
        {
            it->second->setSegmentMode(mode_);
            return it->second;
        }
        Ptr<SilhouetteEditor> ed = SilhouetteEditor::create();
        ed->setImage(image_);
        const FrameMasks& fm = masks_[objects_[object]];
        auto m = fm.find(frame);
        if (m != fm.end())
        {
            ed->loadMask(m->second);
            ed->clearHistory();  // loading is not an edit of the user's
        }
        ed->setSegmentMode(mode_);
        editors_[key] = ed;
        return ed;
    }

    // The editor's silhouette becomes the frame's mask once the user has changed it.
    void commitEditor()
    {
        if (!editor_)
            return;
        if (!editor_->canUndo() && !editor_->canRedo())
            return;  // untouched: the loaded mask (if any) stands
        Mat mask;
        editor_->getMask(mask);
        FrameMasks& fm = masks_[objectName()];
        const bool had = fm.count(frame_) > 0;
        if (countNonZero(mask) > 0)
        {
            if (!had || norm(fm[frame_], mask, NORM_INF) > 0)
                modified_ = true;
            fm[frame_] = mask;
            keyMarks_[objectName()].insert(frame_);
        }
        else if (had)
        {
            fm.erase(frame_);
            modified_ = true;
        }
    }

    void gotoFrame(int f)
    {
        f = std::min(std::max(f, 0), frameCount_ - 1);
        if (f == frame_)
            return;
        commitEditor();
        frame_ = f;
        loadFrame();
    }

    void gotoObject(int o)
    {
        commitEditor();
        object_ = o;
        editor_ = editorFor(object_, frame_);
        dirty_ = true;
    }

    void save()
    {
        commitEditor();
        for (auto& e : editors_)
        {
            if (!e.second->canUndo() && !e.second->canRedo())
                continue;
            Mat mask;
            e.second->getMask(mask);
            FrameMasks& fm = masks_[objects_[e.first.first]];
            if (countNonZero(mask) > 0)
                fm[e.first.second] = mask;
            else
                fm.erase(e.first.second);
        }
        ObjectMasks out;
        for (const std::string& name : objects_)
            out[name] = masks_[name];
        writeMasks(opt_.masks, out);
        modified_ = false;
        int total = 0;
        for (const auto& om : out)
            total += int(om.second.size());
        status_ = format("saved %d mask(s) to %s", total, opt_.masks.c_str());
        info(g_, "annotate: " + status_);
        dirty_ = true;
    }

    // ---- input --------------------------------------------------------------------------------

    static void onMouse(int event, int x, int y, int flags, void* self)
    {
        static_cast<AnnotateApp*>(self)->mouse(event, Point(x, y), flags);
    }

    // Window pixel w: the view shows frame pixel p = viewport_.imagePixelAt(w); the editor works
    // in frame pixels only.
    void mouse(int event, Point w, int flags)
    {
        const bool onView = Rect(Point(), viewport_.getViewSize()).contains(w);
        const Point p = viewport_.imagePixelAt(w);
        const bool onFrame = onView && Rect(Point(), frameSize_).contains(p);
        // The wheel is not bound: Qt's highgui magnifies its own view on it (a second zoom
        // that would push the status lines out of the window), whatever the callback does.
        if (event == EVENT_MBUTTONDOWN ||
            (event == EVENT_LBUTTONDOWN && (flags & EVENT_FLAG_CTRLKEY)))
        {
            panFrom_ = w;
            return;
        }
        if (panFrom_.x >= 0 && (event == EVENT_MBUTTONUP || event == EVENT_LBUTTONUP))
        {
            panTo(w);
            panFrom_ = Point(-1, -1);
            return;
        }
        if (event == EVENT_MOUSEMOVE)
        {
            if (panFrom_.x >= 0)
                panTo(w);
            cursorView_ = onView ? w : Point(-1, -1);
            cursor_ = onFrame ? p : Point(-1, -1);
            dirty_ = true;
            return;
        }
        if (!onFrame)
            return;
        if (event == EVENT_LBUTTONDOWN)
        {
            int c, a;
            if (editor_->hasOpenContour())
            {
                const int open = editor_->getContourCount() - 1;
                const std::vector<Point> anchors = editor_->getAnchors(open);
                if (anchors.size() >= 3 && norm(anchors.front() - p) <= grabRadius())
                    editor_->closeContour();
                else
                    editor_->addPoint(p);
            }
            else if (editor_->findAnchor(p, grabRadius(), c, a))
            {
                dragContour_ = c;
                dragAnchor_ = a;
            }
            else
                editor_->addPoint(p);
            dirty_ = true;
        }
        else if (event == EVENT_LBUTTONUP && dragContour_ >= 0)
        {
            const Point from = editor_->getAnchors(dragContour_)[dragAnchor_];
            if (from != p)
                editor_->moveAnchor(dragContour_, dragAnchor_, p);
            dragContour_ = dragAnchor_ = -1;
            dirty_ = true;
        }
        else if (event == EVENT_RBUTTONDOWN)
        {
            int c, a;
            if (editor_->hasOpenContour())
                editor_->closeContour();
            else if (editor_->findAnchor(p, grabRadius(), c, a))
                editor_->removeAnchor(c, a);
            dirty_ = true;
        }
    }

    // kGrabRadius window pixels in frame pixels (at least one frame pixel).
    double grabRadius() const { return std::max(1.0, kGrabRadius / viewport_.getScale()); }

    void panTo(Point w)
    {
        viewport_.pan(Point2d(w - panFrom_));
        panFrom_ = w;
        viewChanged();
    }

    // Zoom about window pixel w (the view's centre when the cursor is not over it).
    void zoomAbout(double factor, Point w)
    {
        const Size v = viewport_.getViewSize();
        const Point2d at = w.x >= 0 ? Point2d(w) : Point2d(0.5 * (v.width - 1),
                                                           0.5 * (v.height - 1));
        viewport_.zoomBy(factor, at);
        viewChanged();
    }

    void viewChanged()
    {
        // The cursor now shows another frame pixel.
        if (cursorView_.x >= 0)
        {
            const Point p = viewport_.imagePixelAt(cursorView_);
            cursor_ = Rect(Point(), frameSize_).contains(p) ? p : Point(-1, -1);
        }
        dirty_ = true;
        logView();
    }

    void logView()
    {
        const Point2d o = viewport_.getOffset();
        info(g_, format("annotate: view scale %.9g offset %.9g %.9g", viewport_.getScale(), o.x,
                        o.y));
    }

    // Returns true to quit. Qt's highgui reports letters upper-case and other keys as X keysyms.
    bool handleKey(int key)
    {
        dirty_ = true;
        status_.clear();
        if (key >= 'A' && key <= 'Z')
            key = key - 'A' + 'a';
        switch (key)
        {
        case 'q': case 27: case 65307:
            return true;
        case 'h':
            help_ = !help_;
            break;
        case 'l':
            mode_ = mode_ == SilhouetteEditor::LIVE_WIRE ? SilhouetteEditor::STRAIGHT
                                                        : SilhouetteEditor::LIVE_WIRE;
            editor_->setSegmentMode(mode_);
            break;
        case 'c': case 13: case 10: case 65293: case 65421:
            if (!editor_->closeContour())
                status_ = "nothing to close (a contour needs 3 anchors)";
            break;
        case 8: case 127: case 65288: case 'b':
            editor_->removeLastPoint();
            break;
        case 'u': case 'z':
            if (!editor_->undo())
                status_ = "nothing to undo";
            break;
        case 'r': case 'y':
            if (!editor_->redo())
                status_ = "nothing to redo";
            break;
        case 'i':
            if (cursor_.x < 0 || !editor_->insertAnchor(cursor_, 3 * grabRadius()))
                status_ = "no segment near the cursor";
            break;
        case 'd':
        {
            int c, a;
            if (cursor_.x >= 0 && editor_->findAnchor(cursor_, grabRadius(), c, a))
                editor_->removeAnchor(c, a);
            else
                status_ = "no anchor under the cursor";
            break;
        }
        case 'x':
            editor_->clear();
            break;
        case 'g':
            propose();
            break;
        case 'n': case '.': case 65363:
            gotoFrame(frame_ + 1);
            break;
        case 'p': case ',': case 65361:
            gotoFrame(frame_ - 1);
            break;
        case ']': case 65366:
            gotoKeyFrame(+1);
            break;
        case '[': case 65365:
            gotoKeyFrame(-1);
            break;
        case 'k':
        {
            std::set<int>& marks = keyMarks_[objectName()];
            if (!marks.erase(frame_))
                marks.insert(frame_);
            break;
        }
        case 'o':
            gotoObject((object_ + 1) % int(objects_.size()));
            break;
        case 'a':
        {
            int n = int(objects_.size()) + 1;
            while (indexOf(format("object%d", n)) >= 0)
                ++n;
            addObject(format("object%d", n));
            gotoObject(int(objects_.size()) - 1);
            status_ = "added " + objectName();
            break;
        }
        case 's':
            save();
            break;
        case 'w':
            screenshot();
            break;
        case '+': case '=': case 65451:
            zoomAbout(kZoomStep, cursorView_);
            break;
        case '-': case '_': case 65453:
            zoomAbout(1.0 / kZoomStep, cursorView_);
            break;
        case '0':
            viewport_.fit();
            viewChanged();
            break;
        case '1':
            zoomAbout(1.0 / viewport_.getScale(), cursorView_);
            break;
        default:
            break;
        }
        return false;
    }

    void gotoKeyFrame(int dir)
    {
        const std::set<int>& marks = keyMarks_[objectName()];
        if (dir > 0)
        {
            auto it = marks.upper_bound(frame_);
            if (it != marks.end())
                gotoFrame(*it);
        }
        else
        {
            auto it = marks.lower_bound(frame_);
            if (it != marks.begin())
                gotoFrame(*std::prev(it));
        }
    }

    // An outline for this frame from the nearest frame that has this object's silhouette,
    // snapped to this frame's edges (good for neighbouring frames; `augocc propagate` proposes
    // from the clones for frames far apart).
    void propose()
    {
        commitEditor();
        if (clones_ && rec_.findCamera(frame_) >= 0)
        {
            const std::vector<String> names = clones_->objectNames();
            if (std::find(names.begin(), names.end(), objectName()) != names.end())
            {
                // The clone's visible part (depth-resolved against the other clones), loaded
                // with snapping: the same outline as proposeSilhouettes(), as editable anchors.
                std::map<String, Mat> visible;
                proposeSilhouettes(*clones_, frame_, rec_.camera(frame_), image_, visible, false);
                if (countNonZero(visible[objectName()]) == 0)
                {
                    status_ = "the clone of " + objectName() + " is hidden in this frame";
                    return;
                }
                editor_->loadMask(visible[objectName()], true);
                status_ = "proposed from the clone, snapped to edges";
                return;
            }
        }
        const FrameMasks& fm = masks_[objectName()];
        int best = -1;
        for (const auto& m : fm)
            if (m.first != frame_ && (best < 0 || std::abs(m.first - frame_) <
                                                      std::abs(best - frame_)))
                best = m.first;
        if (best < 0)
        {
            status_ = "no other frame has a silhouette of " + objectName() + " to propose from";
            return;
        }
        editor_->loadMask(fm.at(best), true);
        status_ = format("proposed from frame %d, snapped to edges", best);
    }

    void screenshot()
    {
        const std::string dir = opt_.screenshotDir.empty()
                                    ? fs::absolute(opt_.masks).parent_path().string()
                                    : opt_.screenshotDir;
        fs::create_directories(dir);
        const std::string path =
            (fs::path(dir) / format("annotate_%s_%04d_%d.png", objectName().c_str(), frame_,
                                    shots_++)).string();
        writeImageAtomically(path, canvas_);  // every write checked (a full disk)
        status_ = "screenshot " + path;
        info(g_, "annotate: " + status_);
    }

    // ---- drawing ------------------------------------------------------------------------------

    void render()
    {
        dirty_ = false;
        const int W = viewport_.getViewSize().width, H = viewport_.getViewSize().height;
        canvas_.create(H + kStatusHeight + kTimelineHeight, W, CV_8UC3);
        canvas_.setTo(Scalar(32, 32, 32));
        // Silhouettes are drawn on the frame at its own resolution, then the view shows it.
        image_.copyTo(frameCanvas_);
        Mat view = frameCanvas_;
        // Other objects' silhouettes of this frame, as thin outlines for context.
        for (size_t o = 0; o < objects_.size(); ++o)
        {
            if (int(o) == object_)
                continue;
            auto it = masks_[objects_[o]].find(frame_);
            if (it == masks_[objects_[o]].end())
                continue;
            std::vector<std::vector<Point>> cs;
            findContours(it->second.clone(), cs, RETR_EXTERNAL, CHAIN_APPROX_SIMPLE);
            drawContours(view, cs, -1, Scalar(200, 120, 120), 1, LINE_8);
        }
        const Point cur = dragContour_ >= 0 ? Point(-1, -1) : cursor_;
        editor_->drawOverlay(view, cur);
        Mat shown = canvas_(Rect(0, 0, W, H));
        viewport_.render(frameCanvas_, shown, Scalar(32, 32, 32));
        if (dragContour_ >= 0 && cursorView_.x >= 0)
            circle(shown, cursorView_, 4, Scalar(0, 0, 255), 1, LINE_AA);
        if (help_)
            drawHelpOverlay(shown, kHelp, int(sizeof(kHelp) / sizeof(kHelp[0])), 120);

        const bool isKey = keyMarks_[objectName()].count(frame_) > 0;
        const bool hasMask = masks_[objectName()].count(frame_) > 0;
        const std::string line1 = format(
            "frame %d/%d%s  object %s (%d/%d)  %s  anchors %d  zoom %.0f%%%s", frame_,
            frameCount_ - 1,
            isKey ? (hasMask ? "  KEY (annotated)" : "  KEY (to do)") : "", objectName().c_str(),
            object_ + 1, int(objects_.size()),
            mode_ == SilhouetteEditor::LIVE_WIRE ? "LIVE WIRE" : "STRAIGHT",
            editor_->getAnchorCount(), 100 * viewport_.getScale(), modified_ ? "  *" : "");
        const std::string line2 = status_.empty() ? std::string("h: help   q: save and quit")
                                                  : status_;
        putText(canvas_, line1, Point(6, H + 18), FONT_HERSHEY_SIMPLEX, 0.45,
                Scalar(230, 230, 230), 1, LINE_AA);
        putText(canvas_, line2, Point(6, H + 38), FONT_HERSHEY_SIMPLEX, 0.45,
                Scalar(150, 220, 255), 1, LINE_AA);
        drawTimeline(canvas_(Rect(0, H + kStatusHeight, W, kTimelineHeight)));
        imshow(kWindow, canvas_);
    }

    void drawTimeline(Mat strip)
    {
        const int W = strip.cols;
        auto xOf = [&](int f) {
            return frameCount_ > 1 ? int(std::lround(double(f) * (W - 1) / (frameCount_ - 1)))
                                   : 0;
        };
        for (int f : keyMarks_[objectName()])
        {
            const bool done = masks_[objectName()].count(f) > 0;
            rectangle(strip, Rect(xOf(f) - 1, 0, 3, strip.rows),
                      done ? Scalar(0, 200, 0) : Scalar(0, 0, 230), FILLED);
        }
        line(strip, Point(xOf(frame_), 0), Point(xOf(frame_), strip.rows - 1),
             Scalar(255, 255, 255), 1);
    }


    Options opt_;
    const Globals& g_;
    Ptr<FrameSource> source_;
    Reconstruction rec_;     // with --clones: cameras for the clone proposals
    Ptr<CloneSet> clones_;
    int frameCount_ = 0;
    Size frameSize_;
    ObjectMasks masks_;
    std::vector<std::string> objects_;
    std::map<std::string, std::set<int>> keyMarks_;
    std::map<std::pair<int, int>, Ptr<SilhouetteEditor>> editors_;
    Ptr<SilhouetteEditor> editor_;
    Mat image_, canvas_, frameCanvas_;
    ImageViewport viewport_;
    Size maxView_;                     // largest view: --max-window less the status lines
    Point cursorView_ = Point(-1, -1); // cursor, window pixels
    Point panFrom_ = Point(-1, -1);    // a pan drag in progress: its last window pixel
    int object_ = 0, frame_ = 0;
    int mode_ = SilhouetteEditor::LIVE_WIRE;
    Point cursor_ = Point(-1, -1);
    int dragContour_ = -1, dragAnchor_ = -1;
    bool dirty_ = true, help_ = false, modified_ = false;
    int shots_ = 0;
    std::string status_;
};

} // namespace

void registerAnnotate(CLI::App& app, Globals& g)
{
    auto opt = std::make_shared<Options>();
    CLI::App* sub = app.add_subcommand(
        "annotate", "trace silhouettes of real objects in key frames (interactive window; "
                    "Intelligent Scissors live wire and straight segments)");
    sub->add_option("--input", opt->input, "video, image folder or printf pattern")->required();
    sub->add_option("--masks", opt->masks,
                    "masks folder MASKS/<object>/%04d.png (read if present, written on save)")
        ->required();
    sub->add_option("--object", opt->objects, "object name(s) to trace (repeatable)");
    sub->add_option("--frame", opt->frame, "frame to start at (default 0)");
    sub->add_option("--tracks", opt->tracks, "tracks.yml for key-frame suggestions");
    sub->add_option("--reconstruction", opt->reconstruction,
                    "reconstruction.yml for key-frame suggestions");
    sub->add_option("--clones", opt->clones,
                    "clones file: the g key proposes outlines from the clones (needs "
                    "--reconstruction)");
    sub->add_option("--suggest", opt->suggest,
                    "mark this many suggested key frames (needs --tracks and/or "
                    "--reconstruction)");
    sub->add_option("--screenshot-dir", opt->screenshotDir,
                    "where the w key saves screenshots (default: beside MASKS)");
    sub->add_option("--max-window", opt->maxWindow,
                    "largest window, WIDTHxHEIGHT: a larger frame is shown scaled to fit (zoom "
                    "in with + about the cursor)")->capture_default_str();
    sub->callback([opt, &g]() {
        requireFile("--input", opt->input);
        if (!opt->tracks.empty())
            requireFile("--tracks", opt->tracks);
        if (!opt->reconstruction.empty())
            requireFile("--reconstruction", opt->reconstruction);
        if (!opt->clones.empty())
            requireFile("--clones", opt->clones);
        if (opt->suggest < 0)
            throw UsageError("--suggest must be >= 0");
        const Size maxWindow = parseSize("--max-window", opt->maxWindow);
        const int status = kStatusHeight + kTimelineHeight;
        if (maxWindow.width < 160 || maxWindow.height < status + 120)
            throw UsageError(format("--max-window %s: at least 160x%d (the frame and %d lines of "
                                    "status)", opt->maxWindow.c_str(), status + 120, status));
        AnnotateApp app(*opt, g, Size(maxWindow.width, maxWindow.height - status));
        app.run();
    });
}

} // namespace augocc_cli
