// The colour legend of snapshots (snapshot.h): VTK's vtkScalarBarActor rendered head-less in a Mesa EGL
// surfaceless context (HeadlessGlContext), read back and placed at the right of the picture.
#include "fss/error.h"
#include "fss/render/colour_maps.h"
#include "fss/render/gl_context.h"
#include "fss/render/snapshot.h"

#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkObject.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkTextProperty.h>
#include <vtkUnsignedCharArray.h>

#include <algorithm>
#include <cstring>

namespace fss::render {
namespace {

// Lets VTK drive the head-less context (as the Rasterizer does).
void onWindowEvent(vtkObject*, unsigned long event, void* clientData, void* callData) {
    auto* context = static_cast<GlContext*>(clientData);
    switch (event) {
    case vtkCommand::WindowMakeCurrentEvent:
        context->makeCurrent();
        break;
    case vtkCommand::WindowIsCurrentEvent:
        *static_cast<bool*>(callData) = context->isCurrent();
        break;
    case vtkCommand::WindowSupportsOpenGLEvent:
    case vtkCommand::WindowIsDirectEvent:
        *static_cast<int*>(callData) = 1;
        break;
    default:
        break;
    }
}

// VTK's messages are off while the legend renders: Debian's GLX-built GLEW logs a harmless failure in an EGL
// context (PLATFORM-NOTES), and a failed render is detected by its pixels instead.
class QuietVtk {
public:
    QuietVtk() : was_(vtkObject::GetGlobalWarningDisplay()) { vtkObject::GlobalWarningDisplayOff(); }
    ~QuietVtk() { vtkObject::SetGlobalWarningDisplay(was_); }
    QuietVtk(const QuietVtk&) = delete;
    QuietVtk& operator=(const QuietVtk&) = delete;

private:
    int was_;
};

} // namespace

Image renderMinAngleLegend(int width, int height, const Rgb& background) {
    if (width < 16 || height < 16) throw InvalidInputError("A legend needs at least 16 × 16 pixels.");
    HeadlessGlContext context; // throws one sentence when there is no OpenGL
    const QuietVtk quiet;
    Image image;
    {
        vtkNew<vtkCallbackCommand> callback;
        callback->SetClientData(static_cast<GlContext*>(&context));
        callback->SetCallback(&onWindowEvent);
        vtkNew<vtkGenericOpenGLRenderWindow> window;
        for (auto event : {vtkCommand::WindowMakeCurrentEvent, vtkCommand::WindowIsCurrentEvent,
                           vtkCommand::WindowSupportsOpenGLEvent, vtkCommand::WindowIsDirectEvent})
            window->AddObserver(event, callback);
        window->SetOwnContext(0);
        window->SetMultiSamples(0);
        window->SetFrameBlitModeToNoBlit();
        window->SetSwapBuffers(0);
        window->SetUseSRGBColorSpace(false);
        window->SetSize(width, height);
        context.makeCurrent();
        window->SetReadyForRendering(true);
        window->InitializeFromCurrentContext();

        // The minimum-angle map of colour_maps.h, one entry per degree.
        vtkNew<vtkLookupTable> table;
        table->SetNumberOfTableValues(61);
        for (int a = 0; a <= 60; ++a) {
            const Rgb c = minAngleColor(a);
            table->SetTableValue(a, c[0] / 255.0, c[1] / 255.0, c[2] / 255.0, 1.0);
        }
        table->SetTableRange(0, 60);
        vtkNew<vtkScalarBarActor> bar;
        bar->SetLookupTable(table);
        bar->SetTitle("Min angle (deg)");
        bar->SetNumberOfLabels(5);
        bar->SetLabelFormat("%.0f");
        bar->SetOrientationToVertical();
        bar->SetPosition(0.05, 0.1);
        bar->SetWidth(0.9);
        bar->SetHeight(0.8);
        bar->SetBarRatio(0.3);
        bar->UnconstrainedFontSizeOn(); // the font sizes below, not scaled to the bar's height
        // Dark text on a light background, light text on a dark one.
        const double luminance = (0.3 * background[0] + 0.59 * background[1] + 0.11 * background[2]) / 255;
        const double ink = luminance > 0.5 ? 0.1 : 0.95;
        for (vtkTextProperty* text : {bar->GetTitleTextProperty(), bar->GetLabelTextProperty()}) {
            text->SetColor(ink, ink, ink);
            text->ShadowOff();
            text->ItalicOff();
            text->SetFontSize(std::clamp(height / 30, 10, 20));
        }
        vtkNew<vtkRenderer> renderer;
        renderer->SetBackground(background[0] / 255.0, background[1] / 255.0, background[2] / 255.0);
        renderer->AddActor2D(bar);
        window->AddRenderer(renderer);
        window->Render();
        vtkNew<vtkUnsignedCharArray> pixels;
        window->GetPixelData(0, 0, width - 1, height - 1, 0, pixels, 0);
        if (pixels->GetNumberOfTuples() != vtkIdType(width) * height || pixels->GetNumberOfComponents() != 3)
            throw Error("The legend could not be rendered (OpenGL gave no image).");
        image.width = width;
        image.height = height;
        image.rgb.resize(std::size_t(width) * std::size_t(height) * 3);
        const std::size_t row = std::size_t(width) * 3;
        for (int y = 0; y < height; ++y) // OpenGL rows start at the bottom
            std::memcpy(&image.rgb[std::size_t(y) * row],
                        pixels->GetPointer(std::size_t(height - 1 - y) * row), row);
        window->RemoveRenderer(renderer);
        window->Finalize();
    }
    context.doneCurrent();
    return image;
}

Image appendRight(const Image& image, const Image& right) {
    if (image.height != right.height)
        throw InvalidInputError("Images placed side by side need the same height.");
    Image out;
    out.width = image.width + right.width;
    out.height = image.height;
    out.rgb.resize(std::size_t(out.width) * std::size_t(out.height) * 3);
    const std::size_t a = std::size_t(image.width) * 3, b = std::size_t(right.width) * 3;
    for (int y = 0; y < out.height; ++y) {
        std::uint8_t* dst = &out.rgb[std::size_t(y) * (a + b)];
        std::copy_n(&image.rgb[std::size_t(y) * a], a, dst);
        std::copy_n(&right.rgb[std::size_t(y) * b], b, dst + a);
    }
    return out;
}

} // namespace fss::render
