// augocc place: the interactive placement of virtual objects (the paper's "interactively through
// a GUI", Section 7). A thin highgui shell over cv::augocc::PlacementEditor: the window forwards
// the mouse and the keys, the editor picks, drags on the ground, turns, scales, snaps, undoes,
// previews the composite and saves scene.yml.

#include "cli_common.hpp"
#include "window_shell.hpp"

#include <cstdlib>
#include <filesystem>

#include <opencv2/highgui.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/augocc.hpp>

namespace augocc_cli {

namespace {

namespace fs = std::filesystem;
using namespace cv;
using namespace cv::augocc;

const char* const kWindow = "augocc place";
const char* const kFrameBar = "frame";
const int kStatusHeight = 66;  // three text lines under the frame
const double kRotateStepDeg = 15.0;
const double kScaleStep = 1.1;
// raise / lower step: 1% of the scene's size (about the error bound of the ground under a drag)
const double kRaiseStep = 0.01;
// sun keys: 5 degrees a press (the estimate's 1-sigma on synthesized footage is about 1 degree,
// its worst error 1.7: a few presses reach any correction), sky share 0.05
const double kSunStepDeg = 5.0;
const double kSkyStep = 0.05;
// frames the sun is estimated from (augocc sun's default)
const int kSunFrames = 6;

const char* const kHelp[][2] = {
    {"left drag", "pick an object and drag it on the ground"},
    {"right click", "move the selected object to the ground point clicked"},
    {"Tab, o", "select the next object"},
    {"[  /  ]", "turn -15 / +15 degrees about the vertical"},
    {"-  /  +, =", "scale down / up by 10%"},
    {"j  /  k", "lower / raise by 1% of the scene size"},
    {"b / f / l / r", "snap behind / in front / left / right of the nearest clone"},
    {"a", "add an object (--add files in turn, else a box) at the cursor"},
    {"e", "estimate the sun from the footage (6 frames)"},
    {"1  /  2", "turn the sun -5 / +5 degrees in azimuth"},
    {"3  /  4", "lower / raise the sun by 5 degrees"},
    {"5  /  6", "sky share -0.05 / +0.05"},
    {"g", "sun off / on (the fixed light without it)"},
    {"x, Delete", "remove the selected object"},
    {"u, z  /  y", "undo  /  redo"},
    {"n, .  /  p, ,", "next  /  previous frame (or the trackbar)"},
    {"s  /  q, Esc", "save scene  /  save and quit"},
    {"w  /  h", "save a screenshot  /  this help"},
};

struct Options
{
    std::string input, reconstruction, clones, scene, out, screenshotDir;
    std::vector<std::string> add;
    int frame = 0;
    double snapGap = 0;
    bool hardEdges = false;
};

class PlaceApp
{
public:
    PlaceApp(const Options& o, const Globals& g) : opt_(o), g_(g) {}

    void run()
    {
        load();
        requireDisplay("place");
        namedWindow(kWindow, WINDOW_AUTOSIZE | WINDOW_GUI_NORMAL);
        setMouseCallback(kWindow, &PlaceApp::onMouse, this);
        if (frames_.size() > 1)
            createTrackbar(kFrameBar, kWindow, nullptr, int(frames_.size()) - 1,
                           &PlaceApp::onTrackbar, this);
        if (frames_.size() > 1)
            setTrackbarPos(kFrameBar, kWindow, frameSlot_);
        render();
        waitKey(50);
        // Where the frame lies on the screen: tests and scripts driving the window with xdotool
        // read this line (the image is shown 1:1 from the rectangle's top-left).
        logWindowImageRect(g_, "place", kWindow);
        bool quit = false;
        while (!quit)
        {
            if (dirty_)
                render();
            const int key = waitKeyEx(10);
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
    void load()
    {
        source_ = FrameSource::open(opt_.input);
        const int count = source_->count();
        if (count <= 0)
            throw UsageError("--input " + opt_.input + ": no frames");
        rec_ = readReconstruction(opt_.reconstruction);
        const Reconstruction& rec = rec_;
        if (rec.imageSize != source_->size())
            throw UsageError(format("--reconstruction %s: image size %dx%d, the frames of "
                                    "--input are %dx%d", opt_.reconstruction.c_str(),
                                    rec.imageSize.width, rec.imageSize.height,
                                    source_->size().width, source_->size().height));
        for (const Camera& c : rec.cameras)
            if (c.frame < count)
                frames_.push_back(c.frame);
        if (frames_.empty())
            throw UsageError("--reconstruction " + opt_.reconstruction + ": no camera for a "
                             "frame of --input");
        const Ptr<CloneSet> clones = CloneSet::load(opt_.clones);
        const VirtualScene scene = readScene(opt_.scene);
        for (const std::string& f : opt_.add)
            loadMeshes(f);  // a bad file is reported now, not when its key is pressed
        PlacementEditor::Params p;
        if (opt_.hardEdges)
            p.supersample = 1;
        editor_ = PlacementEditor::create(rec, clones, scene, p);
        frameSlot_ = -1;
        for (size_t i = 0; i < frames_.size(); ++i)
            if (frames_[i] == opt_.frame)
                frameSlot_ = int(i);
        if (frameSlot_ < 0)
            throw UsageError(format("--frame %d: not a frame of --input with a camera in "
                                    "--reconstruction (frames %d..%d)", opt_.frame,
                                    frames_.front(), frames_.back()));
        loadFrame();
    }

    void loadFrame()
    {
        const int f = frames_[frameSlot_];
        source_->seek(f);
        Mat image;
        if (!source_->read(image) || image.empty())
            throw UsageError(format("--input %s: cannot read frame %d", opt_.input.c_str(), f));
        editor_->setFrame(f, image);
        dirty_ = true;
    }

    void gotoSlot(int slot)
    {
        slot = std::min(std::max(slot, 0), int(frames_.size()) - 1);
        if (slot == frameSlot_)
            return;
        frameSlot_ = slot;
        loadFrame();
        if (frames_.size() > 1 && getTrackbarPos(kFrameBar, kWindow) != slot)
            setTrackbarPos(kFrameBar, kWindow, slot);
    }

    void save()
    {
        if (editor_->getObjectCount() == 0)
        {
            status_ = "nothing saved: the scene has no object";
            return;
        }
        editor_->save(outPath());
        status_ = "saved " + outPath();
        info(g_, "place: " + status_);
        dirty_ = true;
    }

    std::string outPath() const { return opt_.out.empty() ? opt_.scene : opt_.out; }

    // ---- input --------------------------------------------------------------------------------

    static void onMouse(int event, int x, int y, int flags, void* self)
    {
        static_cast<PlaceApp*>(self)->mouse(event, Point(x, y), flags);
    }

    static void onTrackbar(int pos, void* self)
    {
        static_cast<PlaceApp*>(self)->gotoSlot(pos);
    }

    void mouse(int event, Point p, int)
    {
        const bool onFrame = Rect(Point(), frameSize()).contains(p);
        if (event == EVENT_MOUSEMOVE)
        {
            cursor_ = onFrame ? p : Point(-1, -1);
            if (editor_->isDragging() && editor_->dragTo(p))
                dirty_ = true;
            return;
        }
        if (event == EVENT_LBUTTONDOWN && onFrame)
        {
            if (!editor_->beginDrag(p))
                editor_->selectObject(-1);
            dirty_ = true;
        }
        else if (event == EVENT_LBUTTONUP && editor_->isDragging())
        {
            editor_->dragTo(p);  // the release point is where the object goes
            editor_->endDrag();
            dirty_ = true;
        }
        else if (event == EVENT_RBUTTONDOWN && onFrame)
        {
            if (!editor_->moveTo(p))
                status_ = "select an object first (left click on it)";
            dirty_ = true;
        }
    }

    Size frameSize() const { return frameSize_.area() ? frameSize_ : source_->size(); }

    bool requireSelection()
    {
        if (editor_->getSelected() >= 0)
            return true;
        status_ = "no object selected (left click on one, or Tab)";
        return false;
    }

    void snap(int side)
    {
        if (!requireSelection())
            return;
        const String clone = editor_->snapToNearestClone(side, opt_.snapGap);
        const char* names[] = {"behind", "in front of", "left of", "right of"};
        status_ = format("snapped %s %s, %g away", names[side], clone.c_str(), opt_.snapGap);
    }

    void estimateSun()
    {
        const std::vector<int> frames = sunEstimationFrames(rec_, kSunFrames);
        std::vector<Mat> images;
        for (int f : frames)
        {
            source_->seek(f);
            Mat img;
            if (!source_->read(img) || img.empty())
            {
                status_ = format("sun: cannot read frame %d of %s", f, opt_.input.c_str());
                return;
            }
            images.push_back(img);
        }
        try
        {
            const SunEstimate e = editor_->estimateSunFromFrames(images, frames);
            status_ = format("sun estimated from %d frames: az %.1f, el %.1f, 1-sigma %.1f "
                             "deg, sky %.2f +- %.2f", e.frames, e.azimuthDeg, e.elevationDeg,
                             e.angularSigmaDeg, e.sky, e.skySigma);
        }
        catch (const cv::Exception& ex)
        {
            status_ = "sun estimation failed: " + ex.err;
        }
        info(g_, "place: " + status_);
    }

    void toggleSun()
    {
        if (editor_->getSun().form != SceneSun::SUN_NONE)
        {
            lastSun_ = editor_->getSun();
            editor_->setSun(SceneSun());
            status_ = "sun off: the fixed light, no shadows";
            return;
        }
        if (lastSun_.form == SceneSun::SUN_NONE)
        {
            lastSun_.form = SceneSun::SUN_AZIMUTH_ELEVATION;  // behind the viewer's right
            lastSun_.azimuthDeg = 135;
            lastSun_.elevationDeg = 45;
        }
        editor_->setSun(lastSun_);
        status_ = "sun on";
    }

    void turnSun(double dAz, double dEl)
    {
        if (!editor_->turnSun(dAz, dEl))
            status_ = "no sun: g turns one on, e estimates it from the footage";
    }

    void changeSky(double d)
    {
        if (!editor_->changeSky(d))
            status_ = "no sun: g turns one on, e estimates it from the footage";
    }

    std::string sunLine() const
    {
        double az, el;
        if (!editor_->getSunAngles(az, el))
            return "no sun (fixed light)   e: estimate it   g: sun on";
        // Short enough for a 640-pixel frame (about 85 characters at this font size).
        std::string s = format("sun az %.1f el %.1f sky %.2f", az, el, editor_->getSun().sky);
        const SunEstimate e = editor_->getSunEstimate();
        if (e.frames > 0)
            s += format("   estimate %.1f / %.1f +-%.1f deg, sky %.2f +-%.2f", e.azimuthDeg,
                        e.elevationDeg, e.angularSigmaDeg, e.sky, e.skySigma);
        return s;
    }

    void add()
    {
        const Point at = cursor_.x >= 0 ? cursor_ : Point(frameSize().width / 2,
                                                          frameSize().height / 2);
        int i;
        if (opt_.add.empty())
            i = editor_->addShape("box", at);
        else
            i = editor_->addObject(opt_.add[nextAdd_++ % opt_.add.size()], at);
        status_ = "added " + editor_->getObject(i).name;
    }

    // Returns true to quit. Qt's highgui reports letters upper-case and other keys as X keysyms.
    bool handleKey(int key)
    {
        dirty_ = true;
        status_.clear();
        if (key >= 'A' && key <= 'Z')
            key = key - 'A' + 'a';
        const int sel = editor_->getSelected();
        switch (key)
        {
        case 'q': case 27: case 65307:
            return true;
        case 'h':
            help_ = !help_;
            break;
        case 9: case 65289: case 'o':
            if (editor_->getObjectCount() > 0)
                editor_->selectObject((sel + 1) % editor_->getObjectCount());
            break;
        case '[':
            if (requireSelection())
                editor_->rotate(-kRotateStepDeg);
            break;
        case ']':
            if (requireSelection())
                editor_->rotate(kRotateStepDeg);
            break;
        case '-': case 65453:
            if (requireSelection())
                editor_->scale(1.0 / kScaleStep);
            break;
        case '+': case '=': case 65451:
            if (requireSelection())
                editor_->scale(kScaleStep);
            break;
        case 'j':
            if (requireSelection())
                editor_->raise(-kRaiseStep * editor_->getSceneSize());
            break;
        case 'k':
            if (requireSelection())
                editor_->raise(kRaiseStep * editor_->getSceneSize());
            break;
        case 'b':
            snap(PlacementEditor::SNAP_BEHIND);
            break;
        case 'f':
            snap(PlacementEditor::SNAP_IN_FRONT);
            break;
        case 'l':
            snap(PlacementEditor::SNAP_LEFT);
            break;
        case 'r':
            snap(PlacementEditor::SNAP_RIGHT);
            break;
        case 'a':
            add();
            break;
        case 'e':
            estimateSun();
            break;
        case 'g':
            toggleSun();
            break;
        case '1':
            turnSun(-kSunStepDeg, 0);
            break;
        case '2':
            turnSun(kSunStepDeg, 0);
            break;
        case '3':
            turnSun(0, -kSunStepDeg);
            break;
        case '4':
            turnSun(0, kSunStepDeg);
            break;
        case '5':
            changeSky(-kSkyStep);
            break;
        case '6':
            changeSky(kSkyStep);
            break;
        case 'x': case 127: case 65535:
            if (requireSelection())
                editor_->removeObject(sel);
            break;
        case 'u': case 'z':
            if (!editor_->undo())
                status_ = "nothing to undo";
            break;
        case 'y':
            if (!editor_->redo())
                status_ = "nothing to redo";
            break;
        case 'n': case '.': case 65363:
            gotoSlot(frameSlot_ + 1);
            break;
        case 'p': case ',': case 65361:
            gotoSlot(frameSlot_ - 1);
            break;
        case 's':
            save();
            break;
        case 'w':
            screenshot();
            break;
        default:
            break;
        }
        return false;
    }

    void screenshot()
    {
        const std::string dir = opt_.screenshotDir.empty()
                                    ? fs::absolute(outPath()).parent_path().string()
                                    : opt_.screenshotDir;
        fs::create_directories(dir);
        const std::string path = (fs::path(dir) / format("place_%04d_%d.png",
                                                          editor_->getFrame(), shots_++))
                                     .string();
        writeImageAtomically(path, canvas_);  // every write checked (a full disk)
        status_ = "screenshot " + path;
        info(g_, "place: " + status_);
    }

    // ---- drawing ------------------------------------------------------------------------------

    void render()
    {
        dirty_ = false;
        const int64 t0 = getTickCount();
        Mat preview;
        editor_->render(preview);
        const double ms = (getTickCount() - t0) * 1000.0 / getTickFrequency();
        frameSize_ = preview.size();
        const int W = preview.cols, H = preview.rows;
        canvas_.create(H + kStatusHeight, W, CV_8UC3);
        canvas_.setTo(Scalar(32, 32, 32));
        Mat view = canvas_(Rect(0, 0, W, H));
        preview.copyTo(view);
        editor_->drawOverlay(view);
        if (help_)
            drawHelpOverlay(view, kHelp, int(sizeof(kHelp) / sizeof(kHelp[0])), 130);
        const int sel = editor_->getSelected();
        std::string what = "no selection";
        if (sel >= 0)
        {
            const SceneObject o = editor_->getObject(sel);
            const Vec3d b = editor_->getGround().toGround(editor_->getBasePoint(sel));
            const char* how = o.placement == SceneObject::PLACE_BEHIND     ? "behind "
                              : o.placement == SceneObject::PLACE_IN_FRONT ? "in front of "
                              : o.placement == SceneObject::PLACE_BESIDE   ? "beside "
                                                                           : "";
            what = format("%s (%d/%d) %s%s  base (%.2f, %.2f, %.2f)", o.name.c_str(), sel + 1,
                          editor_->getObjectCount(), how, o.anchor.c_str(), b[0], b[1], b[2]);
        }
        const std::string line1 = format("frame %d  %s%s  preview %.0f ms", editor_->getFrame(),
                                         what.c_str(), editor_->isModified() ? "  *" : "", ms);
        const std::string line2 = status_.empty() ? std::string("h: help   q: save and quit")
                                                  : status_;
        putText(canvas_, line1, Point(6, H + 18), FONT_HERSHEY_SIMPLEX, 0.45,
                Scalar(230, 230, 230), 1, LINE_AA);
        putText(canvas_, sunLine(), Point(6, H + 38), FONT_HERSHEY_SIMPLEX, 0.45,
                Scalar(120, 230, 255), 1, LINE_AA);
        putText(canvas_, line2, Point(6, H + 58), FONT_HERSHEY_SIMPLEX, 0.45,
                Scalar(150, 220, 255), 1, LINE_AA);
        imshow(kWindow, canvas_);
    }


    Options opt_;
    const Globals& g_;
    Ptr<FrameSource> source_;
    Ptr<PlacementEditor> editor_;
    Reconstruction rec_;
    SceneSun lastSun_;  // the sun g turned off
    std::vector<int> frames_;  // frames with a camera, in order
    int frameSlot_ = 0;
    size_t nextAdd_ = 0;
    Size frameSize_;
    Mat canvas_;
    Point cursor_ = Point(-1, -1);
    bool dirty_ = true, help_ = false;
    int shots_ = 0;
    std::string status_;
};

} // namespace

void registerPlace(CLI::App& app, Globals& g)
{
    auto opt = std::make_shared<Options>();
    CLI::App* sub = app.add_subcommand(
        "place", "place the virtual objects of a scene file interactively: drag them on the "
                 "ground, turn, scale, snap against a clone, with the composite shown live");
    sub->add_option("--input", opt->input, "video, image folder or printf pattern")->required();
    sub->add_option("--reconstruction", opt->reconstruction, "reconstruction.yml")->required();
    sub->add_option("--clones", opt->clones, "clones.yml.gz (augocc clone)")->required();
    sub->add_option("--scene", opt->scene, "scene.yml: the virtual objects (composite's file)")
        ->required();
    sub->add_option("--out", opt->out, "where s and q save the scene (default: --scene itself)");
    sub->add_option("--add", opt->add, "mesh file (OBJ, PLY, glTF...) the a key adds "
                    "(repeatable: in turn)");
    sub->add_option("--frame", opt->frame, "frame to start at (default 0)");
    sub->add_option("--snap-gap", opt->snapGap, "gap the snap keys leave to the clone's face, "
                    "world units (default 0)");
    sub->add_option("--screenshot-dir", opt->screenshotDir,
                    "where the w key saves screenshots (default: beside the saved scene)");
    sub->add_flag("--hard-edges", opt->hardEdges, "preview with the paper's per-pixel depth test "
                  "(composite --hard-edges)");
    sub->callback([opt, &g]() {
        requireFile("--input", opt->input.find('%') == std::string::npos ? opt->input : ".");
        requireFile("--reconstruction", opt->reconstruction);
        requireFile("--clones", opt->clones);
        requireFile("--scene", opt->scene);
        for (const std::string& f : opt->add)
            requireFile("--add", f);
        if (!(opt->snapGap >= 0))
            throw UsageError("--snap-gap must be >= 0");
        PlaceApp app(*opt, g);
        app.run();
    });
}

} // namespace augocc_cli
