// A project outside augocc's tree that finds it with find_package(augocc) and links it.
#include <cmath>
#include <cstdio>
#include <opencv2/augocc.hpp>

int main()
{
    using namespace cv::augocc;
    Camera c = Camera::orthographic(cv::Matx33d::eye(), cv::Vec3d(0, 0, 10), 2.0,
                                    cv::Point2d(5, 5));
    const cv::Point2d p = c.project(cv::Vec3d(1, 2, 3));
    if (std::abs(p.x - 7) > 1e-12 || std::abs(p.y - 9) > 1e-12)
    {
        std::printf("wrong projection %f %f\n", p.x, p.y);
        return 1;
    }
    std::printf("consumer ok\n");
    return 0;
}
