//! The error-versus-time plot of `bench quality`: one colour per scene,
//! every setting a point, the Pareto front of each scene joined by a line.

use std::path::Path;

use plotters::prelude::*;

/// One measured setting.
pub struct Point {
    pub series: String,
    pub label: String,
    pub ms: f64,
    pub error: f64,
    pub pareto: bool,
}

const SIZE: (u32, u32) = (1100, 700);
const COLORS: [RGBColor; 9] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(188, 189, 34),
];

/// Draws the plot and writes it as a PNG.
pub fn plot(points: &[Point], path: &Path) -> anyhow::Result<()> {
    // The labels use egui's bundled font, so no system font is needed.
    plotters::style::register_font("sans-serif", FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT)
        .map_err(|_| anyhow::anyhow!("the bundled font is not a font"))?;
    let mut buffer = vec![255u8; (SIZE.0 * SIZE.1 * 3) as usize];
    draw(points, &mut buffer).map_err(|e| anyhow::anyhow!("cannot draw the plot: {e}"))?;
    let rgb = image::RgbImage::from_raw(SIZE.0, SIZE.1, buffer).ok_or_else(|| anyhow::anyhow!("plot buffer size"))?;
    let rgba = image::DynamicImage::ImageRgb8(rgb).to_rgba8();
    octovox::io::png::save_png(&rgba, path, octovox::io::atomic::WriteOptions::default())?;
    Ok(())
}

fn draw(points: &[Point], buffer: &mut [u8]) -> Result<(), Box<dyn std::error::Error>> {
    let root = BitMapBackend::with_buffer(buffer, SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    let ms = points.iter().map(|p| p.ms.max(0.01));
    let (lo, hi) = ms.fold((f64::MAX, 0.0f64), |(lo, hi), m| (lo.min(m), hi.max(m)));
    let top = points.iter().map(|p| p.error).fold(0.0f64, f64::max).max(0.01) * 1.1;
    let mut chart = ChartBuilder::on(&root)
        .caption("Error against time per frame (lower left is better)", ("sans-serif", 26))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(64)
        .build_cartesian_2d((lo * 0.7..hi * 1.4).log_scale(), 0.0..top)?;
    chart.configure_mesh().x_desc("ms per frame (log)").y_desc("mean FLIP").label_style(("sans-serif", 16)).draw()?;
    let mut series: Vec<&str> = points.iter().map(|p| p.series.as_str()).collect();
    series.sort_unstable();
    series.dedup();
    for (i, name) in series.iter().enumerate() {
        let color = COLORS[i % COLORS.len()];
        let mine: Vec<&Point> = points.iter().filter(|p| p.series == *name).collect();
        let name = name.to_string();
        let mut front: Vec<(f64, f64)> = mine.iter().filter(|p| p.pareto).map(|p| (p.ms.max(0.01), p.error)).collect();
        front.sort_by(|a, b| a.0.total_cmp(&b.0));
        chart
            .draw_series(LineSeries::new(front, color.stroke_width(2)))?
            .label(name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
        chart.draw_series(mine.iter().map(|p| {
            let style = if p.pareto { color.filled() } else { color.stroke_width(1) };
            Circle::new((p.ms.max(0.01), p.error), 5, style)
        }))?;
        chart.draw_series(mine.iter().filter(|p| p.pareto).map(|p| {
            Text::new(p.label.clone(), (p.ms.max(0.01), p.error), ("sans-serif", 13).into_font().color(&color))
        }))?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}
